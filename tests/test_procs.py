"""Children never outlive their parent: a pool worker and its own child die when the parent is killed."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import time

import pytest

from support.processes import depth_below, descendants, wait_gone

# A parent that starts a worker (anomalygen.procs.child_pool) which starts its own isolation child,
# both blocking forever, as learn's pool worker and its per-execution process do.
PARENT = textwrap.dedent("""
    import pathlib, sys, time
    from anomalygen.procs import child_pool

    def grandchild(marker):
        print("a library talking on stdout")  # must reach stderr, never the parent's stdout
        sys.stdout.flush()
        pathlib.Path(marker).write_text("printed")
        time.sleep(600)

    def worker(marker):
        with child_pool(1) as pool:
            pool.submit(grandchild, marker).result()

    if __name__ == "__main__":
        with child_pool(1) as pool:
            pool.submit(worker, sys.argv[1]).result()
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_the_parent_takes_its_workers_and_their_children_along(tmp_path):
    script = tmp_path / "parent.py"
    script.write_text(PARENT)
    marker = tmp_path / "printed"
    proc = subprocess.Popen([sys.executable, str(script), str(marker)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 180  # spawn imports the package twice over on a loaded machine
        while time.monotonic() < deadline and not marker.is_file():
            time.sleep(0.2)
        below = descendants(proc.pid)
        assert marker.is_file() and any(depth_below(proc.pid, p) == 2 for p in below), "the grandchild never ran"
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        assert wait_gone(below, 15.0) == set()
    finally:
        proc.kill()
    out, err = proc.communicate(timeout=10)
    assert out == b"" and b"a library talking on stdout" in err


# A script that starts a stage the way the benchmarks do (subprocess.run with end_with_parent).
SCRIPT = textwrap.dedent("""
    import subprocess, sys
    from anomalygen.procs import end_with_parent

    subprocess.run([sys.executable, "-c", "import time; print('started', flush=True); time.sleep(600)"],
                   preexec_fn=end_with_parent)
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_stage_a_killed_script_started_ends_with_it(tmp_path):
    script = tmp_path / "script.py"
    script.write_text(SCRIPT)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        assert proc.stdout.readline() == b"started\n"
        below = descendants(proc.pid)
        assert len(below) == 1
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        assert wait_gone(below, 10.0) == set()
    finally:
        proc.kill()
