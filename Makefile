# Two entry points: `make demo` and `make test`. Both create .venv on first use.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT ?= out/demo

.PHONY: demo test lint bench clean

$(STAMP): pyproject.toml constraints.txt
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	# torch first, pinned: the CPU build on local disk (a bare `torch` pulls CUDA).
	$(BIN)/pip install -q torch==2.13.0
	$(BIN)/pip install -q -c constraints.txt -e '.[test]'
	# pyrender pins PyOpenGL==3.1.0, which breaks mujoco's EGL: install it without deps
	# (its other dependencies are in pyproject.toml, PyOpenGL>=3.1.7 among them).
	$(BIN)/pip install -q --no-deps 'pyrender==0.1.45'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/avatarsim demo --out $(OUT)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports

test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

bench: $(STAMP)
	$(BIN)/avatarsim bench

clean:
	rm -rf $(VENV) out .pytest_cache .hypothesis
