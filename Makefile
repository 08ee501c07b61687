# Two commands for a new user: `make run` (the pipeline) and `make test` (the suite).
# TORCH_SPEC picks the torch build: the default is the CPU wheel; GPU users pass their own,
# e.g. make run TORCH_SPEC="torch==2.13.0 --index-url https://download.pytorch.org/whl/cu128"
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
TORCH_SPEC ?= torch==2.13.0
STAMP := $(VENV)/.installed

.PHONY: install run test lint docs docs-build bench ui clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q $(TORCH_SPEC)
	$(BIN)/python -m pip install -q -e ".[all,test]"
	touch $(STAMP)

install: $(STAMP)

# The stages run `python -m pipelines...`: the venv must come first on PATH.
run: $(STAMP)
	PATH="$(abspath $(BIN)):$$PATH" $(BIN)/dvc repro

# Two test processes (pytest-xdist), a file's tests kept together so that its fixtures are built
# once: the suite is CPU-bound and CI has 2 cores. The slowest tests are listed at the end.
test: $(STAMP) lint docs-build
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --durations=15

# The documentation site (docs/, mkdocs.yml): `make docs` serves it on http://127.0.0.1:8000;
# `make test` builds it with --strict, so a broken link or a missing API reference fails CI (not
# --quiet: with it, mkdocs 1.6 prints the warnings away and strict mode passes a broken link).
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs serve

docs-build: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir $(VENV)/site

# ruff (style, imports, line length) and mypy (every zonegraph function fully annotated)
lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python -m bench.replay_bench
	$(BIN)/python -m bench.zonegraph_bench
	$(BIN)/python -m bench.search_bench

# The MLflow dashboard on the project's tracking store: training and evaluation runs.
ui: $(STAMP)
	$(BIN)/python -m eval.tracking relocate
	$(BIN)/mlflow ui --backend-store-uri sqlite:///mlflow.db --port $${PORT:-5000}

clean:
	rm -rf $(VENV) data mlruns site
