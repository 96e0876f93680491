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

.PHONY: venv demo test test-fast bench lint format clean

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

test: $(STAMP)
	$(PY) -m pytest -n 2 --dist loadgroup --timeout 900

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
