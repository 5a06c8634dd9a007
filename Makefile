# The two commands in the README work on a fresh machine with Python 3.11, git and make.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
# Stamp files make each install step run only when pyproject.toml changes.
STAMP_RUN := $(VENV)/.installed-run
STAMP_DEV := $(VENV)/.installed-dev
OUT ?= out

.PHONY: demo test test-slow test-browser browser-deps lint format bench docs compare-experiments clean

$(BIN)/python:
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "error: $(PYTHON) not found; set PYTHON=/path/to/python3.11" >&2; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP_RUN): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[all]"
	@touch $@

$(STAMP_DEV): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[dev,all]"
	@touch $@ $(STAMP_RUN)

# The end-to-end DAA demo (simulate -> detect -> track -> alert -> report), then the ch2
# simulator figures.
demo: $(STAMP_RUN)
	$(BIN)/skyradar demo -o $(OUT)/demo
	$(BIN)/skyradar experiment ch2 -o $(OUT)/ch2

# Debian's chromium for the headless display test (Playwright drives it; Playwright's own browser
# download is never used). Installed here, once and visibly, never from inside a test: apt-get runs
# only when $(CHROMIUM) is missing, and needs root (CI runs `make test` as root).
CHROMIUM := /usr/bin/chromium

$(CHROMIUM):
	@if [ "$$(id -u)" != 0 ]; then \
	  echo "error: $(CHROMIUM) is missing and installing it needs root: run 'sudo apt-get install -y chromium' (Debian/Ubuntu), then 'make test' again" >&2; \
	  exit 1; fi
	@echo "browser-deps: $(CHROMIUM) missing; running apt-get update && apt-get install -y chromium"
	DEBIAN_FRONTEND=noninteractive apt-get update -qq
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium
	@test -x $(CHROMIUM) || { echo "error: apt-get install chromium did not provide $(CHROMIUM)" >&2; exit 1; }

browser-deps: $(CHROMIUM)

# Unit tests, the docstring examples of every module (--doctest-modules, see pyproject.toml) and
# the headless-Chromium display test.
# Two workers, one per core; loadscope keeps a module's shared fixtures (one simulated run) in
# one worker instead of building them twice.
test: $(STAMP_DEV) browser-deps
	SKYRADAR_SCREENSHOT_DIR=$(OUT)/browser $(BIN)/python -m pytest -q -m "not slow" -n 2 --dist loadscope

test-slow: $(STAMP_DEV)
	$(BIN)/python -m pytest -q -m "slow"

# The browser test alone: headless Chromium drives the live display. The screenshot lands in
# $(OUT)/browser/display.png.
test-browser: $(STAMP_DEV) browser-deps
	SKYRADAR_SCREENSHOT_DIR=$(OUT)/browser $(BIN)/python -m pytest -q -m browser tests/browser

lint: $(STAMP_DEV)
	$(BIN)/ruff check src tests examples scripts
	$(BIN)/ruff format --check src tests examples scripts

format: $(STAMP_DEV)
	$(BIN)/ruff format src tests examples scripts
	$(BIN)/ruff check --fix src tests examples scripts

# The documentation site, offline, warnings as errors: open $(OUT)/docs/index.html. The results page,
# the CLI reference and the API reference are generated from docs/results/ and the package.
docs: $(STAMP_DEV)
	$(BIN)/python -m sphinx -b html -W --keep-going -q docs/source $(OUT)/docs

# Every per-frame stage's benchmark and the whole-flight one (flight: no longer inside chain); each prints
# its JSON as the last line.
bench: $(STAMP_RUN)
	@for name in sim chain flight process track state; do $(BIN)/skyradar bench $$name --json || exit 1; done

# Every experiment at its defaults on BASE and on HEAD (default the checkout's HEAD), each version in its
# own worktree under $(OUT)/compare; prints the values that differ, timings left out (RTOL: relative
# tolerance of measured floats, default exact). BASE is required.
compare-experiments: $(STAMP_RUN)
	@test -n "$(BASE)" || { echo "make compare-experiments: give BASE=<commit>" >&2; exit 2; }
	$(BIN)/python scripts/compare_experiments.py $(BASE) $(or $(HEAD),HEAD) --work $(OUT)/compare $(if $(RTOL),--rtol $(RTOL))

clean:
	rm -rf $(VENV) $(OUT) build *.egg-info src/*.egg-info
