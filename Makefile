# Two commands do everything: `make run` and `make test`.
# Both create .venv when it is missing and (re)install the package when pyproject.toml changes.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test lint docs bench clean system-deps firmware flash

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# The package with what the tests and the documentation site need (the test and docs
# extras): `make test` builds the site in a test, `make docs` builds it for reading.
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	touch $(STAMP)

# The large-N study (studies/large_n/*.toml) takes CPU-hours, so its merged results are
# kept in the repository and read into REPORT.md's section on it and claim 4.
LARGE_N := studies/large_n/results/large_n_0.75.nc studies/large_n/results/large_n_star.nc

run: $(STAMP)
	$(BIN)/metrosync reproduce --quick --out results --large-n $(LARGE_N)

# System packages some tests use (Chromium, the AVR toolchain, simavr): installed when
# missing and possible, never fatal; tests without them skip and say which is missing.
system-deps:
	@./tools/system-deps

# On every core (pytest-xdist): the tests of a module that share a module-scoped fixture
# stay on one worker (loadgroup, tests/conftest.py), the rest are dealt out one by one.
# Each test's time goes to build/test-times.xml: benchmarks/suite_times.py sums it per folder.
test: $(STAMP) system-deps
	$(BIN)/python -m pytest -n auto --dist loadgroup --junitxml=build/test-times.xml

# The gate-logger firmware (needs gcc-avr and avr-libc): firmware/gate-logger/build/gate-logger.hex.
# Options pass through and a changed one rebuilds: make firmware CHANNELS=7; make flash
# CHANNELS=7 PORT=/dev/ttyACM0 (avrdude). Without the toolchain it says what to install.
firmware:
	$(MAKE) -C firmware/gate-logger

flash:
	$(MAKE) -C firmware/gate-logger flash

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples docs/conf.py
	$(BIN)/mypy

# The documentation site, into docs/_build/html, every gallery example run; any warning
# is an error. Offline: MathJax comes from a package, the theme bundles its assets.
docs: $(STAMP)
	$(BIN)/python -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@echo "open docs/_build/html/index.html"

bench: $(STAMP)
	$(BIN)/python benchmarks/kernel.py

clean:
	rm -rf $(VENV) results build dist *.egg-info firmware/gate-logger/build \
		docs/_build docs/gallery docs/sg_execution_times.rst
