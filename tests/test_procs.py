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
    import sys, time
    from anomalygen.procs import child_pool

    def grandchild():
        print("a library talking on stdout")  # must reach stderr, never the parent's stdout
        sys.stdout.flush()
        time.sleep(600)

    def worker():
        with child_pool(1) as pool:
            pool.submit(grandchild).result()

    if __name__ == "__main__":
        with child_pool(1) as pool:
            pool.submit(worker).result()
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_the_parent_takes_its_workers_and_their_children_along(tmp_path):
    script = tmp_path / "parent.py"
    script.write_text(PARENT)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120  # spawn imports the package twice over on a loaded machine
        below: set[int] = set()
        while time.monotonic() < deadline:
            below = descendants(proc.pid)
            if any(depth_below(proc.pid, p) == 2 for p in below):
                break
            time.sleep(0.2)
        assert any(depth_below(proc.pid, p) == 2 for p in below), "the grandchild never started"
        time.sleep(1.0)  # let the grandchild print
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        assert wait_gone(below, 15.0) == set()
    finally:
        proc.kill()
    out, err = proc.communicate(timeout=10)
    assert out == b"" and b"a library talking on stdout" in err
