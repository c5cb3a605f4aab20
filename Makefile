# Two entry points for a fresh machine (see README):
#   make book   - create the environment if needed, vendor MathJax, build the book (executes every chapter)
#   make test   - create the environment if needed, run the test suite
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.tiltlab-installed
MATHJAX_VERSION ?= 3.2.2
MATHJAX_DIR := book/_vendor/mathjax

.PHONY: env book test lint rerun browser-test benchmarks registry clean

env: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --upgrade pip
	$(PY) -m pip install -e ".[book,dev,compare,learn]"
	$(PY) -m ipykernel install --sys-prefix --name python3 >/dev/null
	touch $(STAMP)

# MathJax is vendored at build time from the npm registry (never committed) so math renders offline.
$(MATHJAX_DIR)/tex-chtml.js:
	bash tools/vendor_mathjax.sh $(MATHJAX_VERSION) $(MATHJAX_DIR)

book: env $(MATHJAX_DIR)/tex-chtml.js
	rm -rf book/_build
	$(VENV)/bin/jupyter-book build book --all -W -n --keep-going

# style and layer contracts (ruff on code and notebooks; import-linter on the package)
lint: env
	$(VENV)/bin/ruff check src tests benchmarks tools notebooks
	$(VENV)/bin/ruff format --check src tests benchmarks tools notebooks
	$(VENV)/bin/lint-imports

test: lint
	$(PY) -m pytest

# every chapter a second time on another data source / parameter set (papermill), then
# `tiltlab report` for real on a converted foreign recording and a small cohort
rerun: env
	$(PY) tools/rerun_chapters.py
	$(PY) tools/report_check.py

browser-test: env
	TILTLAB_REQUIRE_BOOK=1 $(PY) -m pytest -m browser

benchmarks: env
	for f in benchmarks/bench_*.py; do $(PY) $$f || exit 1; done

registry: env
	$(PY) tools/make_registry.py

clean:
	rm -rf book/_build book/_vendor
