# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP_RUN := $(VENV)/.installed-run
STAMP_DEV := $(VENV)/.installed-dev

CHROMIUM := /usr/bin/chromium
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# The documentation site: built offline, warnings are errors.
DOCS_HTML := docs/_build/html
SPHINXOPTS ?=

.PHONY: demo test quick lint bench clean browser-deps docs

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP_RUN): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[all]'
	touch $@

$(STAMP_DEV): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $@ $(STAMP_RUN)

demo: $(STAMP_RUN)
	$(BIN)/bayesgrasp demo
	@echo "The web page: $(BIN)/bayesgrasp serve, then open http://127.0.0.1:8000/"
	@if [ -f $(DOCS_HTML)/index.html ]; then \
		echo "The documentation: $(CURDIR)/$(DOCS_HTML)/index.html (rebuild it with: make docs)"; \
	else \
		echo "The documentation: build it with 'make docs', then open $(CURDIR)/$(DOCS_HTML)/index.html"; \
	fi

# The Sphinx site (docs/): the tutorials run, the reference generated from the code, no
# network. -E: every page read again, so that no warning hides in a cached page.
docs: $(STAMP_DEV)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/sphinx-build -j auto -b html -E -W --keep-going -q \
		-d docs/_build/doctrees $(SPHINXOPTS) docs $(DOCS_HTML)
	@echo "bayesgrasp: the documentation is in $(DOCS_HTML)/index.html"

lint: $(STAMP_DEV)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks
	$(BIN)/mypy src

# The browser tests drive Debian's chromium (tests/web/test_browser.py skips them, saying why,
# where it cannot be installed).
browser-deps:
	@test -x $(CHROMIUM) || { command -v apt-get >/dev/null && $(SUDO) apt-get update -qq && $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } || echo "bayesgrasp: could not install chromium; the browser tests will be skipped"

# The docs are built once here; tests/docs/test_docs.py checks that build (BAYESGRASP_DOCS_HTML).
test: lint browser-deps docs
	BAYESGRASP_DOCS_HTML=$(CURDIR)/$(DOCS_HTML) $(BIN)/python -m pytest -q

# The quick run while working: no MuJoCo, Dask, browser or long statistical tests (CI runs
# `make test`, which runs them all).
quick: $(STAMP_DEV)
	$(BIN)/python -m pytest -q -m "not physics and not dask and not browser and not slow"

bench: $(STAMP_RUN)
	for f in benchmarks/bench_*.py; do $(BIN)/python $$f || exit 1; done

clean:
	rm -rf $(VENV) build dist *.egg-info src/*.egg-info .pytest_cache .mypy_cache .ruff_cache
	rm -rf docs/_build docs/auto_tutorials docs/reference/generated docs/reference/api.rst
