# fuzzoff: every target creates its own virtual environment, so a fresh clone needs nothing else.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
MULTITOOL := build/node/node_modules/.bin/sarif-multitool

.PHONY: install demo test test-tools test-lowest test-sitl check bench fuzz new-rule clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev,fleet]'
	touch $(STAMP)

install: $(STAMP)

# Lint the bundled corpus (it holds deliberately damaged files, so exit 2 is expected): the HTML
# report and the errors on the terminal, from one lint.
demo: $(STAMP)
	$(BIN)/fuzzoff lint corpora --fail-on error --quiet --format html --output build/demo-report.html --format terminal || [ $$? -le 2 ]
	@echo "HTML report written to $$(pwd)/build/demo-report.html"

# The SARIF validator (Microsoft's SARIF Multitool, from npm) and Chromium for the browser tests.
$(MULTITOOL):
	mkdir -p build/node
	npm install --prefix build/node --no-audit --no-fund --silent @microsoft/sarif-multitool@5.7.0
	chmod u+x build/node/node_modules/@microsoft/sarif-multitool-linux/Sarif.Multitool

test-tools: $(MULTITOOL)
	@command -v chromium >/dev/null 2>&1 || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } || echo "fuzzoff: chromium could not be installed: the browser tests will be skipped (and fail under CI)"

test: $(STAMP) test-tools
	$(BIN)/python -m pytest -q -n 2

# The oldest versions pyproject.toml allows, from a built wheel: first the plain install alone,
# run from outside the source tree (lint, gate, rule and profiles without Hypothesis; fuzz says
# how to add it), then with the fuzz extra the tests that exercise every dependency (readers,
# reports, fuzz campaigns). CI runs it after `make test`: about 3 minutes.
LOWEST := build/lowest
LOWEST_TESTS := tests/test_corpora.py tests/test_terminal_report.py tests/test_html_report.py \
	tests/test_fuzz_campaigns.py tests/test_cli.py tests/test_config.py tests/test_packaging.py

test-lowest:
	rm -rf $(LOWEST)
	$(PY) -m venv $(LOWEST)/venv
	$(LOWEST)/venv/bin/pip install -q --upgrade pip
	$(LOWEST)/venv/bin/pip wheel -q --no-deps -w $(LOWEST)/dist .
	$(PY) tests/lower_bounds.py > $(LOWEST)/constraints.txt
	$(LOWEST)/venv/bin/pip install -q -c $(LOWEST)/constraints.txt $(LOWEST)/dist/fuzzoff-*.whl
	cd $(LOWEST) && venv/bin/python $(CURDIR)/tests/wheel_smoke.py $(CURDIR)/corpora
	$(LOWEST)/venv/bin/pip install -q -c $(LOWEST)/constraints.txt \
		"$$(ls $(LOWEST)/dist/fuzzoff-*.whl)[fuzz]" pytest pytest-xdist junitparser
	$(LOWEST)/venv/bin/pip list --format freeze
	$(LOWEST)/venv/bin/python -m pytest -q -n 2 -p no:cacheprovider $(LOWEST_TESTS)

# The scenario matrix on the PX4 SITL bundles in ../shared/px4-sitl (fuzzoff.sitl.scenarios.
# scenarios_for), each run compared with the gate model (two PX4 at a time, instances 2 and 3;
# about a minute a run, 1.15 adds 40 s of boot).
# `make test` runs only the short live check.
test-sitl: $(STAMP)
	FUZZOFF_SITL_MATRIX=1 $(BIN)/python -m pytest -q -n 2 tests/test_sitl_live.py tests/test_sitl.py tests/test_ros2_live.py tests/test_fuzz_against_ros2.py

check: $(STAMP)
	$(BIN)/ruff check fuzzoff tests bench corpora docs scripts
	$(BIN)/mypy

# A pip install compiles the package to bytecode; an editable one only when Python may write it
# (PYTHONDONTWRITEBYTECODE stops that), so compile first: no process should pay for it.
bench: $(STAMP)
	$(BIN)/python -m compileall -q fuzzoff
	$(BIN)/python -m bench

# A longer campaign than the short seeded ones `make test` runs; SEED=n picks another seed.
# fuzzoff's own known problems (fuzzoff/fuzz/known.py) are left out, as for every user; their
# reproducers are rebuilt with `$(BIN)/python corpora/fuzz/build.py`, and `make test` checks
# that each still fails (tests/test_fuzz_reproducers.py).
fuzz: $(STAMP)
	$(BIN)/fuzzoff fuzz --budget 600 --seed $${SEED:-1} --save-dir build/fuzz-reproducers --format junit --output build/fuzz-junit.xml

# A new rule's page, check and corpus cases, and the docs (docs/contributing.md, "Add a rule"):
# make new-rule CODE=OFB204 NAME=switch-before-stream ARGS="--severity error --sent-stream"
new-rule: $(STAMP)
	@test -n "$(CODE)" -a -n "$(NAME)" || { echo "usage: make new-rule CODE=OFBnnn NAME=rule-name [ARGS=...]"; exit 2; }
	$(BIN)/python scripts/add_rule.py $(CODE) $(NAME) $(ARGS)

clean:
	rm -rf $(VENV) build .pytest_cache .mypy_cache .hypothesis
