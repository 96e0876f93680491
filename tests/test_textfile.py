"""``anomalygen.textfile``: every way a user's file can be wrong as text is one UserError line naming
the file, the line where one applies, and what to do."""

import pytest

from anomalygen.errors import UserError
from anomalygen.textfile import read_lines, read_text, split_lines

WHAT = "--tasks-text file"


def _refused(path, **kw) -> str:
    with pytest.raises(UserError) as info:
        read_lines(path, what=WHAT, **kw)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    return message


def test_a_folder_a_missing_path_and_a_binary_file_are_named_as_such(tmp_path):
    assert "a folder, not a --tasks-text file" in _refused(tmp_path)
    assert "--tasks-text file not found" in _refused(tmp_path / "nope.txt")
    binary = tmp_path / "ls"
    binary.write_bytes(b"\x7fELF\x02\x01\x01\x00\x00\x00" + bytes(range(256)))
    assert "a binary file" in _refused(binary)


def test_text_not_in_utf8_gives_the_line_column_and_byte_and_says_save_as_utf8(tmp_path):
    latin1 = tmp_path / "latin1.txt"
    latin1.write_bytes("The kettle is on.\nLa cafeti\u00e8re est allum\u00e9e.\n".encode("latin-1"))
    message = _refused(latin1)
    assert f"{latin1}, line 2: not UTF-8 text (byte 0xe8 at column 10)" in message
    assert "save the --tasks-text file as UTF-8" in message
    utf16 = tmp_path / "utf16.txt"
    utf16.write_text("The kettle is on.\n", encoding="utf-16")
    assert "saved as UTF-16; save it as UTF-8" in _refused(utf16)


def test_a_line_over_the_limit_names_its_number_its_length_and_the_limit(tmp_path):
    path = tmp_path / "long.txt"
    path.write_text("short\n" + "a" * 100_000 + "\n")
    message = _refused(path, max_chars=1000, limit_reason="one hazard")
    assert f"{path}, line 2: 100,000 characters, more than the 1,000" in message and "(one hazard)" in message
    assert read_lines(path, what=WHAT) == ["short", "a" * 100_000]  # no limit asked, none applied


def test_lines_are_the_editors_lines(tmp_path):
    path = tmp_path / "t.txt"
    path.write_bytes("\ufeffone\r\ntwo \u2028 still two\n\nfour".encode())
    assert read_text(path, what=WHAT).startswith("one")  # a UTF-8 byte-order mark is dropped
    assert read_lines(path, what=WHAT) == ["one", "two \u2028 still two", "", "four"]
    assert split_lines("a\n") == ["a"] and split_lines("") == []
