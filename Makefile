# The two commands a new user needs: `make demo` and `make test`. Everything else is for developers.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip
# llama-cpp-python only ships as source: build it once and keep the wheel outside the checkout.
WHEELHOUSE ?= $(HOME)/.cache/anomalygen/wheels
STAMP := $(VENV)/.installed
EXTRAS := dev,llamacpp,ray
DEMO_OUT ?= runs/demo
export MUJOCO_GL ?= egl
export PYOPENGL_PLATFORM ?= egl
export HF_HUB_OFFLINE := 1
export TRANSFORMERS_OFFLINE := 1
export TOKENIZERS_PARALLELISM := false
export RAY_AUTH_MODE := disabled
export MPLCONFIGDIR := $(CURDIR)/.cache/matplotlib

.PHONY: venv demo test test-fast bench lint format clean system-deps

venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q --upgrade pip wheel setuptools
	$(PIP) install -q -c constraints.txt torch==2.13.0
	@mkdir -p $(WHEELHOUSE)
	@ls $(WHEELHOUSE)/llama_cpp_python-*.whl >/dev/null 2>&1 || { \
	  echo "Building llama-cpp-python once (several minutes on 2 cores); the wheel is cached in $(WHEELHOUSE)"; \
	  CMAKE_BUILD_PARALLEL_LEVEL=2 $(PIP) wheel -q --no-deps -w $(WHEELHOUSE) "llama-cpp-python>=0.3"; }
	$(PIP) install -q -c constraints.txt --find-links $(WHEELHOUSE) -e ".[$(EXTRAS)]"
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/anomalygen run --out $(DEMO_OUT)

test: $(STAMP) system-deps
	$(PY) -m pytest -n 2 --dist loadgroup --timeout 900

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
