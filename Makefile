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

.PHONY: help venv dev dev-all install docs docs-site test test-rust test-python demo lint fmt bench clean

help:
	@echo "make demo   - simulated harvest with plots (no hardware, no test tools)"
	@echo "make test   - set up .venv, build, run cargo test and pytest"
	@echo "make lint   - cargo fmt --check, clippy -D warnings, ruff, mypy stubtest"
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
	$(VENV)/bin/maturin develop --release -q

test-rust:
	cargo test --release -p softarm-core

# The optional extras whose tests run in CI: Ray sweeps, the Cosserat rod, the rerun view,
# the rendered bush.
TEST_EXTRAS := test,sweep,cosserat,viz,render,ros

dev-all: venv
	$(VENV)/bin/maturin develop --release --extras $(TEST_EXTRAS) -q

test-python: dev-all
	$(PY) -m pytest -q

test: dev-all test-rust
	$(PY) -m pytest -q

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

lint: dev
	cargo fmt --all -- --check
	cargo clippy --release --workspace --all-targets -- -D warnings
	$(VENV)/bin/ruff check python tests examples
	$(VENV)/bin/ruff format --check python tests examples
	$(PY) -m mypy.stubtest softarm._core --allowlist .stubtest-allowlist

fmt:
	cargo fmt --all
	$(VENV)/bin/ruff format python tests examples
	$(VENV)/bin/ruff check --fix python tests examples

bench: dev
	cargo bench -p softarm-core
	$(PY) -m pytest tests/benchmarks --benchmark-only --benchmark-columns=min,median,mean,ops,rounds -q

clean:
	rm -rf $(VENV) target
