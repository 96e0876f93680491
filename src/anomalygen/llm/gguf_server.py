"""Child-process entry point: serve one GGUF file with llama.cpp's OpenAI-compatible server.

Why a separate process: llama.cpp is native code, and native code can crash (a segfault in
``decode`` took down whole pytest workers when it ran in-process). Here a crash kills only this
process; the parent (``anomalygen.llm.local_server``) sees the dropped connection, fails that one
item and starts a fresh server for the next. The server comes from the prebuilt ``xllamacpp`` wheel,
so nothing is compiled on the user's machine.

Protocol with the parent: one line ``READY <address>`` on stdout once the model is loaded and the
server listens; llama.cpp's own log goes to stderr (the parent sends it to a file). The process
exits when its stdin closes, so a parent that dies never leaves a server running.

Run by hand: ``python -m anomalygen.llm.gguf_server --model FILE.gguf``.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading

READY = "READY"


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", required=True, help="GGUF file to serve")
    parser.add_argument("--n-ctx", type=int, default=4096, help="context size in tokens")
    parser.add_argument("--threads", type=int, default=None, help="default: the cores usable, less one, 1 to 4")
    parser.add_argument("--port", type=int, default=0, help="0: any free port (the address is printed)")
    return parser.parse_args(argv)


def serve(args: argparse.Namespace):
    """Load the model and start listening on 127.0.0.1; returns the running ``xllamacpp.Server``."""
    import xllamacpp

    from anomalygen.llm.local_server import default_threads

    params = xllamacpp.CommonParams()
    params.model.path = args.model
    params.n_ctx = args.n_ctx
    params.n_parallel = 1  # one slot: the whole context serves the request in flight
    threads = args.threads or default_threads()
    params.cpuparams.n_threads = threads
    params.cpuparams_batch.n_threads = threads
    params.hostnames = ["127.0.0.1"]  # never reachable from outside this machine
    params.port = args.port
    params.ui = False
    return xllamacpp.Server(params)


def exit_when_parent_leaves() -> None:
    """Block until stdin closes (the parent ended or closed the pipe), then leave at once."""
    try:
        while sys.stdin.buffer.read(1024):
            pass
    finally:
        os._exit(0)


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    if not os.path.isfile(args.model):
        print(f"GGUF model file not found: {args.model}", file=sys.stderr)
        raise SystemExit(2)
    server = serve(args)
    print(f"{READY} {server.listening_address}", flush=True)
    watcher = threading.Thread(target=exit_when_parent_leaves, name="parent-watch", daemon=True)
    watcher.start()
    watcher.join()


if __name__ == "__main__":
    main()
