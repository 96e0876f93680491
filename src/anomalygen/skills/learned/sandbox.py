"""Sandboxed ``compute_reward(state)`` code: an AST allow-list, then a rate-limited subprocess.

LLM-written reward code is untrusted. RoboGen imports it with ``importlib`` and swallows its errors;
we instead (1) parse it and accept only a small allow-listed subset of Python (arithmetic,
comparisons, control flow, calls of allow-listed builtins and ``np.<allow-listed>`` functions, no
imports, no attribute other than ``np.<name>``, nothing starting with ``_``), (2) run it in a
separate interpreter with CPU, memory, file-size and file-descriptor limits, with a read-only state
and no ``print``/``open``/``getattr``, and (3) dry-run it on one state before any training so a bad
function fails the item before minutes of SAC are spent. Two independent layers: an escape has to
beat both the static check and the OS limits.
"""

from __future__ import annotations

import ast
import json
import math
import os
import select
import subprocess
import sys
from typing import Any

from anomalygen.errors import AnomalygenError


class RewardCodeError(AnomalygenError):
    """Reward code was rejected by the checker, failed, timed out or was killed."""


#: Builtins the code may call; everything else (open, eval, getattr, type, vars, ...) is absent.
SAFE_BUILTINS = ("abs", "min", "max", "float", "int", "bool", "len", "sum", "range", "round", "enumerate", "zip", "all", "any")

#: numpy functions reachable as ``np.<name>`` (``np.linalg.norm`` is exposed as ``np.norm`` too).
NUMPY_FUNCS = (
    "array", "asarray", "zeros", "ones", "dot", "cross", "sqrt", "exp", "log", "tanh", "abs", "clip",
    "minimum", "maximum", "sum", "mean", "min", "max", "square", "arccos", "arcsin", "arctan2", "cos",
    "sin", "tan", "sign", "norm", "where", "isfinite", "pi", "inf", "linspace", "prod", "float64",
)

_ALLOWED_NODES = (
    ast.Module, ast.FunctionDef, ast.arguments, ast.arg, ast.Return, ast.Assign, ast.AugAssign,
    ast.AnnAssign, ast.If, ast.For, ast.While, ast.Break, ast.Continue, ast.Pass, ast.Expr,
    ast.Name, ast.Load, ast.Store, ast.Constant, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare,
    ast.IfExp, ast.Call, ast.keyword, ast.Subscript, ast.Slice, ast.Tuple, ast.List, ast.Dict,
    ast.ListComp, ast.GeneratorExp, ast.comprehension, ast.Attribute,
    ast.Add, ast.Sub, ast.Mult, ast.Div, ast.FloorDiv, ast.Mod, ast.Pow, ast.USub, ast.UAdd, ast.Not,
    ast.And, ast.Or, ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.In, ast.NotIn,
    ast.Is, ast.IsNot,
)

_MAX_SOURCE = 20_000
_MAX_CONST_STR = 200


def check_code(source: str) -> ast.Module:
    """Parse and allow-list-check reward code; raise :class:`RewardCodeError` naming the first problem."""
    if not isinstance(source, str) or not source.strip():
        raise RewardCodeError("reward code is empty")
    if len(source) > _MAX_SOURCE:
        raise RewardCodeError(f"reward code longer than {_MAX_SOURCE} characters")
    try:
        tree = ast.parse(source, mode="exec")
    except SyntaxError as exc:
        raise RewardCodeError(f"syntax error: {exc.msg} (line {exc.lineno})") from exc

    defined: set[str] = set()
    for stmt in tree.body:
        if isinstance(stmt, ast.FunctionDef):
            defined.add(stmt.name)
        elif isinstance(stmt, ast.Assign) and all(isinstance(t, ast.Name) for t in stmt.targets):
            defined.update(t.id for t in stmt.targets)  # module constants
        elif isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
            continue  # docstring
        else:
            raise RewardCodeError(f"line {stmt.lineno}: only function definitions and constants allowed at top level")
    if "compute_reward" not in defined:
        raise RewardCodeError("no function compute_reward(state) defined")

    callable_names = set(SAFE_BUILTINS) | defined
    for node in ast.walk(tree):
        where = f"line {getattr(node, 'lineno', '?')}"
        if not isinstance(node, _ALLOWED_NODES):
            raise RewardCodeError(f"{where}: {type(node).__name__} is not allowed")
        if isinstance(node, ast.FunctionDef) and (node.decorator_list or node.returns is not None):
            raise RewardCodeError(f"{where}: decorators and annotations are not allowed")
        if isinstance(node, ast.Name):
            if node.id.startswith("_"):
                raise RewardCodeError(f"{where}: names starting with '_' are not allowed")
            if node.id in ("np", "state") and isinstance(node.ctx, ast.Store):
                raise RewardCodeError(f"{where}: cannot rebind '{node.id}'")
        if isinstance(node, ast.arg) and node.arg.startswith("_"):
            raise RewardCodeError(f"{where}: names starting with '_' are not allowed")
        if isinstance(node, ast.Attribute):
            if not (isinstance(node.value, ast.Name) and node.value.id == "np" and node.attr in NUMPY_FUNCS):
                raise RewardCodeError(f"{where}: attribute '.{node.attr}' is not allowed (only np.<allow-listed>)")
        if isinstance(node, ast.Call):
            fn = node.func
            ok = (isinstance(fn, ast.Name) and fn.id in callable_names) or isinstance(fn, ast.Attribute)
            if not ok:
                raise RewardCodeError(f"{where}: call of '{ast.unparse(fn)}' is not allowed")
        if isinstance(node, ast.Constant):
            if isinstance(node.value, str | bytes) and len(node.value) > _MAX_CONST_STR:
                raise RewardCodeError(f"{where}: string constant too long")
            if isinstance(node.value, bytes):
                raise RewardCodeError(f"{where}: bytes constants are not allowed")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            exp = node.right
            if not (isinstance(exp, ast.Constant) and isinstance(exp.value, int | float) and abs(exp.value) <= 16):
                raise RewardCodeError(f"{where}: exponent must be a small numeric constant")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod) and isinstance(node.left, ast.Constant) and isinstance(node.left.value, str):
            raise RewardCodeError(f"{where}: string formatting is not allowed")
    return tree


# --------------------------------------------------------------------------- the worker process

# Runs in a fresh ``python -I`` interpreter. Reads the code, then one JSON state per line; answers one
# JSON line each. Limits are set before the code is compiled, so even the compile is bounded.
_WORKER = r'''
import json, math, resource, sys, types
lim = json.loads(sys.argv[1])
import numpy
resource.setrlimit(resource.RLIMIT_AS, (lim["mem"], lim["mem"]))
resource.setrlimit(resource.RLIMIT_CPU, (lim["cpu"], lim["cpu"]))
resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
resource.setrlimit(resource.RLIMIT_NOFILE, (4, 4))
try:
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
except (ValueError, OSError):
    pass
sys.setrecursionlimit(200)
inp, out = sys.stdin, sys.stdout
np_ns = {n: getattr(numpy, n) for n in lim["np"] if hasattr(numpy, n)}
np_ns["norm"] = numpy.linalg.norm
np_obj = types.SimpleNamespace(**np_ns)
import builtins
safe = {n: getattr(builtins, n) for n in lim["builtins"]}
def freeze(x):
    if isinstance(x, dict):
        return types.MappingProxyType({k: freeze(v) for k, v in x.items()})
    if isinstance(x, list):
        return tuple(freeze(v) for v in x)
    return x
src = inp.readline()
env = {"__builtins__": safe, "np": np_obj}
try:
    exec(compile(json.loads(src), "<reward>", "exec"), env)
    fn = env["compute_reward"]
except BaseException as e:
    out.write(json.dumps({"error": "compile: " + type(e).__name__}) + "\n"); out.flush(); sys.exit(0)
out.write(json.dumps({"ready": True}) + "\n"); out.flush()
for line in inp:
    try:
        r = fn(freeze(json.loads(line)))
        if isinstance(r, numpy.ndarray) and r.size == 1:
            r = r.item()
        if isinstance(r, bool) or not isinstance(r, (int, float, numpy.floating, numpy.integer)):
            msg = {"error": "compute_reward returned " + type(r).__name__ + ", not a number"}
        else:
            r = float(r)
            msg = {"reward": r} if math.isfinite(r) else {"error": "reward is not finite"}
    except RecursionError:
        msg = {"error": "RecursionError"}
    except MemoryError:
        msg = {"error": "MemoryError"}
    except BaseException as e:
        msg = {"error": type(e).__name__ + ": " + str(e)[:200]}
    out.write(json.dumps(msg) + "\n"); out.flush()
'''


class SandboxedReward:
    """A checked ``compute_reward`` living in a limited subprocess; call it with a state dict.

    One persistent worker serves every step (spawning per step would cost ~50 ms). Any timeout,
    crash or error kills the worker and raises :class:`RewardCodeError`: reward code that fails once
    is not trusted again.
    """

    def __init__(self, source: str, *, timeout_s: float = 1.0, mem_mb: int = 512, cpu_s: int = 60):
        check_code(source)
        self.source = source
        self.timeout_s = timeout_s
        limits = {"mem": mem_mb * 2**20, "cpu": cpu_s, "np": list(NUMPY_FUNCS), "builtins": list(SAFE_BUILTINS)}
        env = {"PATH": "/usr/bin:/bin", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        self._proc: subprocess.Popen | None = subprocess.Popen(
            [sys.executable, "-I", "-c", _WORKER, json.dumps(limits)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=env,
            cwd="/",
            text=True,
            close_fds=True,
        )
        self._send(json.dumps(source))
        reply = self._receive(max(timeout_s, 20.0))  # interpreter + numpy start-up
        if "ready" not in reply:
            self.close()
            raise RewardCodeError(f"reward code failed to load: {reply.get('error', reply)}")

    def _send(self, line: str) -> None:
        assert self._proc is not None and self._proc.stdin is not None
        try:
            self._proc.stdin.write(line + "\n")
            self._proc.stdin.flush()
        except (BrokenPipeError, OSError) as exc:
            self.close()
            raise RewardCodeError("reward process died") from exc

    def _receive(self, timeout: float) -> dict[str, Any]:
        assert self._proc is not None and self._proc.stdout is not None
        ready, _, _ = select.select([self._proc.stdout], [], [], timeout)
        if not ready:
            self.close()
            raise RewardCodeError(f"reward code timed out after {timeout:.1f}s (killed)")
        line = self._proc.stdout.readline()
        if not line:
            code = self._proc.poll()
            self.close()
            raise RewardCodeError(f"reward process was killed (exit {code})")
        try:
            msg = json.loads(line)
        except json.JSONDecodeError as exc:
            self.close()
            raise RewardCodeError("reward process sent garbage") from exc
        if not isinstance(msg, dict):
            self.close()
            raise RewardCodeError("reward process sent garbage")
        return msg

    def __call__(self, state: dict[str, Any]) -> float:
        if self._proc is None:
            raise RewardCodeError("reward sandbox is closed")
        self._send(json.dumps(_jsonable(state)))
        msg = self._receive(self.timeout_s)
        if "error" in msg:
            self.close()
            raise RewardCodeError(f"reward code failed: {msg['error']}")
        value = msg.get("reward")
        if not isinstance(value, int | float) or not math.isfinite(value):
            self.close()
            raise RewardCodeError("reward process sent a non-number")
        return float(value)

    def dry_run(self, state: dict[str, Any]) -> float:
        """Evaluate once before training; the error names what is wrong with the code."""
        return self(state)

    def close(self) -> None:
        proc, self._proc = self._proc, None
        if proc is not None:
            if proc.poll() is None:
                proc.kill()
            proc.wait(timeout=5)
            for stream in (proc.stdin, proc.stdout):
                try:
                    if stream is not None:
                        stream.close()
                except OSError:
                    pass

    def __enter__(self) -> SandboxedReward:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:  # noqa: BLE001
            pass


def _jsonable(x: Any) -> Any:
    """State dicts hold numpy arrays and scalars; JSON needs lists and floats."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if hasattr(x, "tolist"):
        return x.tolist()
    return x


def is_sandbox_available() -> bool:
    return os.name == "posix"
