# `make demo` and `make test` do all set-up on a fresh machine with only python3 (3.11) present.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-$(shell cksum requirements-dev.txt | cut -d' ' -f1)

.PHONY: demo test test-core lint bench extension clean

$(STAMP): requirements-dev.txt
	$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 11) else "bpy 5.0.1 needs Python 3.11")'
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements-dev.txt
	rm -f $(VENV)/.installed-*
	touch $@

demo: $(STAMP)
	$(BIN)/python tools/demo.py --out demo_output

test: $(STAMP)
	$(BIN)/python -m pytest -q -p no:cacheprovider tests

# the bpy-free, quick tier: no Blender, no sockets, nothing that takes seconds (markers in pytest.ini)
test-core: $(STAMP)
	$(BIN)/python -m pytest -q -p no:cacheprovider -m "not bpy and not slow and not network" --ignore=tests/blender tests

# ruff (pyproject.toml) on the bpy-free foundations, pyflakes everywhere, pyright on core/, sources/, takes/
# (pyright's PyPI wheel bundles its JavaScript and runs it with the node on PATH; offline once installed)
lint: $(STAMP)
	$(BIN)/ruff check kinect_retarget/core kinect_retarget/sources kinect_retarget/takes
	$(BIN)/ruff check --select F,E9 kinect_retarget tests tools benchmarks
	$(BIN)/pyright

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

extension: $(STAMP)
	$(BIN)/python tools/build_extension.py

clean:
	rm -rf demo_output dist
