# fuzzoff: every target creates its own virtual environment, so a fresh clone needs nothing else.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install demo test check bench fuzz clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev]'
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/fuzzoff lint corpora --fail-on error --output build/demo-report.json --format json || [ $$? -eq 1 ]
	$(BIN)/fuzzoff lint corpora --fail-on error || [ $$? -eq 1 ]
	@echo "report written to $$(pwd)/build/demo-report.json"

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2

check: $(STAMP)
	$(BIN)/ruff check fuzzoff tests bench
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python -m bench

fuzz: $(STAMP)
	$(BIN)/fuzzoff fuzz --budget 300 --seed 1

clean:
	rm -rf $(VENV) build .pytest_cache .mypy_cache .hypothesis
