"""The one reader of text files a user hands the CLI: a ``--tasks-text`` file, a ``--tasks``
tasks.jsonl, a ``--config`` TOML (and the run folder's own JSONL files, read the same way).

Whatever is wrong with such a file as text (a folder given for it, a path that does not exist, a
binary file, text saved as UTF-16 or Latin-1 rather than UTF-8, a line longer than its format
allows) ends as one ``UserError`` line naming the file, the line where one applies, and what to do,
before any caller parses it. What the text then means (JSON, TOML, hazard lines) is the caller's
business.

Lines are what an editor shows: the text is split at ``\\n`` only (a ``\\r`` before it dropped), so
line numbers match the editor's, and a U+2028 inside a JSON string stays in its record (Python's
``str.splitlines`` would cut the record in two there).
"""

from __future__ import annotations

from pathlib import Path

from anomalygen.errors import UserError

# Byte-order marks of UTF-16, which Windows tools (PowerShell's ``>``, Notepad's "Unicode") write:
# named as such, since "not UTF-8" alone would not tell the user which setting to change.
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
_UTF8_BOM = "\ufeff"


def read_text(path: str | Path, *, what: str) -> str:
    """The whole file as text, strictly UTF-8 (a leading UTF-8 byte-order mark dropped).

    ``what`` names the file for the user, as a noun: "--tasks-text file", "config file".
    """
    path = Path(path)
    if path.is_dir():
        raise UserError(f"{path}: a folder, not a {what}; give the path of the file itself")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise UserError(f"{path}: {what} not found; check the path") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot read the {what}: {(exc.strerror or str(exc)).lower()}") from None
    if data.startswith(_UTF16_BOMS):
        raise UserError(f"{path}: the {what} is saved as UTF-16; save it as UTF-8")
    if b"\0" in data:
        raise UserError(f"{path}: a binary file, not a {what}; give a plain-text file saved as UTF-8")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise UserError(f"{path}, line {line}: not UTF-8 text (byte 0x{data[exc.start]:02x} at column {column}); "
                        f"save the {what} as UTF-8") from None
    return text.removeprefix(_UTF8_BOM)


def split_lines(text: str) -> list[str]:
    """The lines of ``text`` as an editor numbers them (line 1 is index 0)."""
    lines = [line.removesuffix("\r") for line in text.split("\n")]
    return lines[:-1] if lines and lines[-1] == "" else lines


def read_lines(path: str | Path, *, what: str, max_chars: int | None = None, limit_reason: str = "") -> list[str]:
    """The file's lines (``read_text``, ``split_lines``); with ``max_chars``, a longer line is refused
    with its number, its length, the limit and ``limit_reason`` (why the format has one)."""
    lines = split_lines(read_text(path, what=what))
    if max_chars is not None:
        for lineno, line in enumerate(lines, start=1):
            if len(line) > max_chars:
                why = f" ({limit_reason})" if limit_reason else ""
                raise UserError(f"{path}, line {lineno}: {len(line):,} characters, more than the {max_chars:,} a "
                                f"line of the {what} may hold{why}; shorten it or split it into lines")
    return lines
