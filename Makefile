# cellsim: set-up and the two main commands.
#   make run    set up everything, then run the default welding scenario
#   make test   set up everything, then run the test suite (its fast share; make test-slow runs
#               the slow share, make lint the static checks of the API; CI runs both too)
# Set-up is idempotent: system packages are installed only when missing, the virtual
# environment is (re)built only when pyproject.toml changes.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
SCENARIO ?= bugnar_5r_weld_cycle
OUT    ?=
PYTEST_ARGS ?=
# Test workers: one per core (pytest-xdist); JOBS=0 (SLOW_JOBS=0) runs in this process.
JOBS   ?= auto
SLOW_JOBS ?= auto

# Debian packages that headless rendering needs (EGL on Mesa, or OSMesa).
SYSTEM_PACKAGES := libegl1 libgl1 libosmesa6 libglu1-mesa
# The browser the replay's tests drive (tests/analysis/test_replay_browser.py): optional,
# installed by browser-deps (test and test-slow run it); without it those tests are skipped.
BROWSER_PACKAGES := chromium

.PHONY: run test test-slow lint setup system-deps browser-deps bench clean

run: setup
	$(BIN)/cellsim run $(SCENARIO) $(if $(OUT),--out $(OUT),)

# The fast share (every test but those marked slow); test-slow runs the slow share (larger
# generated campaigns, convergence studies), which .ci/run runs after the fast one.
# The fast share's workers take whole test files (--dist loadfile): a file's module fixtures
# (its shared runs) are computed once, not once per worker; the slow share's long campaign
# files are spread test by test.
test: setup browser-deps
	@$(BIN)/python -m pytest -m "not slow" -n $(JOBS) --dist loadfile $(PYTEST_ARGS); rc=$$?; \
	  if [ $$rc -eq 5 ]; then echo "no tests collected: failing" >&2; exit 1; fi; exit $$rc

test-slow: setup browser-deps
	@$(BIN)/python -m pytest -m slow -n $(SLOW_JOBS) $(PYTEST_ARGS); rc=$$?; \
	  if [ $$rc -eq 5 ]; then echo "no tests collected: failing" >&2; exit 1; fi; exit $$rc

# Static checks of the API face (the files pyproject.toml's [tool.mypy] names).
LINT_FILES := sim/__init__.py sim/api sim/pipeline/sweep/evaluation.py examples tests/api/test_api.py

lint: setup
	$(BIN)/ruff check $(LINT_FILES)
	$(BIN)/python -m mypy

bench: setup
	$(BIN)/python benchmarks/run_all.py

setup: system-deps $(VENV)/.installed

system-deps:
	@bash scripts/install-system-deps.sh $(SYSTEM_PACKAGES)

browser-deps:
	@bash scripts/install-system-deps.sh --optional $(BROWSER_PACKAGES)

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' || \
	  { echo "cellsim needs Python 3.11 or newer (PYTHON=$(PYTHON))"; exit 1; }
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache
