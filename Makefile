# Developer habits as targets. Everything builds into .venv; a fresh machine needs only
# cargo, python3 (3.11+), pip and make.
VENV ?= .venv
PY := $(VENV)/bin/python
PIP := $(VENV)/bin/pip
export VIRTUAL_ENV := $(abspath $(VENV))
export PATH := $(abspath $(VENV))/bin:$(PATH)
# Non-interactive plotting everywhere (CI, headless machines).
export MPLBACKEND ?= Agg
# Offscreen OpenGL for the rendered bush (MuJoCo): EGL, Mesa's software rasteriser without a GPU.
export MUJOCO_GL ?= egl
# maturin develop hands pip every requirement of every extra; pip says "Ignoring X: markers
# 'extra == ...' don't match your environment" for each one not asked for (about 20
# lines). Quiet pip prints warnings and errors only; cargo's progress still shows.
export PIP_QUIET ?= 1

.PHONY: help venv dev dev-all install docs docs-site test test-rust test-python wheel demo lint fmt bench clean

help:
	@echo "make demo   - simulated harvest with plots (no hardware, no test tools)"
	@echo "make test   - build the wheel once, cargo test, then pytest against the wheel installed"
	@echo "              in a fresh $(WHEEL_VENV) with no Rust toolchain on the PATH"
	@echo "make wheel  - the release abi3 wheel, into $(WHEEL_DIR)/ (pip install needs no cargo)"
	@echo "make lint   - cargo fmt --check, clippy -D warnings, ruff, mypy (strict) on python/softarm, mypy stubtest"
	@echo "make bench  - criterion and pytest-benchmark"
	@echo "make docs   - regenerate the generated docs (docs/planning.md, docs/experiments.md and their figures)"
	@echo "make docs-site - the documentation site with its API reference, into site/ (the docs extra)"

$(VENV)/.stamp: pyproject.toml
	python3 -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q "maturin>=1.9,<2"
	touch $@

venv: $(VENV)/.stamp

# One optimised build of the extension, installed in place with the test extras.
dev: venv
	$(VENV)/bin/maturin develop --release --extras test -q

# The same build with the runtime dependencies only: what a user of `make demo` needs.
install: venv
	@echo "building the Rust extension (release, about two minutes on a first build)..."
	$(VENV)/bin/maturin develop --release

test-rust:
	cargo test --release -p softarm-core

# The optional extras whose tests run in CI: Ray sweeps, the Cosserat rod, the rerun view,
# the rendered bush, the detector's training (JAX CPU: installs in ~15 s, its tests ~1 min).
TEST_EXTRAS := test,sweep,cosserat,viz,render,ros,foxglove,train

dev-all: venv
	$(VENV)/bin/maturin develop --release --extras $(TEST_EXTRAS) -q

# pytest against the editable .venv (the source tree): the quick loop while developing.
test-python: dev-all
	$(PY) -m pytest -q $(PYTEST_ARGS)

# The release wheel users install: abi3 (one wheel for CPython >= 3.11, pyproject's
# [tool.maturin] features), built once into $(WHEEL_DIR)/. It compiles the same crates in the
# same target/release as `maturin develop --release` and `cargo test --release`.
WHEEL_DIR := target/wheels
wheel: venv
	rm -f $(WHEEL_DIR)/softarm-*.whl
	$(VENV)/bin/maturin build --release --out $(WHEEL_DIR)

# `make test` tests what users install: the wheel with CI's extras, in a fresh virtual
# environment whose PATH has no cargo or rustc (nor .venv), so that nothing can build from
# source; pytest imports softarm from that environment's site-packages, never python/
# (tests/test_installed_wheel.py checks both). PYTEST_ARGS picks tests: `make test
# PYTEST_ARGS=tests/test_kinematics.py`.
WHEEL_VENV ?= .venv-wheel
PYTEST_ARGS ?=
empty :=
space := $(empty) $(empty)
NO_RUST_PATH := $(abspath $(WHEEL_VENV))/bin:$(subst $(space),:,$(strip $(foreach d,$(subst :, ,$(PATH)),$(if $(filter $(abspath $(VENV))/bin,$(d))$(wildcard $(d)/cargo $(d)/rustc),,$(d)))))
IN_WHEEL_VENV := env PATH="$(NO_RUST_PATH)" VIRTUAL_ENV=$(abspath $(WHEEL_VENV)) SOFTARM_WHEEL_VENV=$(abspath $(WHEEL_VENV))

test: wheel test-rust
	rm -rf $(WHEEL_VENV)
	$(IN_WHEEL_VENV) python3 -m venv $(WHEEL_VENV)
	$(IN_WHEEL_VENV) $(WHEEL_VENV)/bin/python -m pip install -q "$$(ls $(WHEEL_DIR)/softarm-*.whl)[$(TEST_EXTRAS)]"
	@$(IN_WHEEL_VENV) sh -c '! command -v cargo && ! command -v rustc' >/dev/null || { echo "cargo or rustc is on the PATH of $(WHEEL_VENV)"; exit 1; }
	$(IN_WHEEL_VENV) $(WHEEL_VENV)/bin/python -P -c 'import softarm; print("testing", softarm.__file__)'
	$(IN_WHEEL_VENV) $(WHEEL_VENV)/bin/python -P -m pytest -q $(PYTEST_ARGS)

# The generated docs: the planning paper's tables and figures, from the code that measures
# them (tests/test_docs_current.py checks that their deterministic columns are current).
docs: dev
	$(PY) -m softarm.planning.report --out docs/planning.md
	$(VENV)/bin/softarm experiment all --out docs/experiments --report docs/experiments.md -q

# The documentation site (mkdocs.yml): the manual pages and an API reference from the
# docstrings and softarm/_core.pyi, built strict (a warning fails it) into site/.
docs-site: venv
	$(VENV)/bin/maturin develop --release --extras docs -q
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

demo: install
	$(VENV)/bin/softarm demo
	@echo
	@echo "softarm is installed in $(VENV), not on your PATH: run $(VENV)/bin/softarm,"
	@echo "or first \`source $(VENV)/bin/activate\` and then \`softarm --help\`."

lint: dev
	cargo fmt --all -- --check
	cargo clippy --release --workspace --all-targets -- -D warnings
	$(VENV)/bin/ruff check python tests examples
	$(VENV)/bin/ruff format --check python tests examples
	$(PY) -m mypy python/softarm
	$(PY) -m mypy.stubtest softarm._core --allowlist .stubtest-allowlist

fmt:
	cargo fmt --all
	$(VENV)/bin/ruff format python tests examples
	$(VENV)/bin/ruff check --fix python tests examples

bench: dev
	cargo bench -p softarm-core
	$(PY) -m pytest tests/benchmarks --benchmark-only --benchmark-columns=min,median,mean,ops,rounds -q

clean:
	rm -rf $(VENV) $(WHEEL_VENV) target
