# Two entry points: `make demo` and `make test`. Both create .venv when missing; so does
# `make docs` (the Sphinx site in docs/_build/html, with the [docs] extra).
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
DEMO_OUT ?= demo-out

.PHONY: demo test lint bench wheel-check docs clean clean-cache

$(STAMP): pyproject.toml setup.py
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev,video,slurm,bullet]"
	touch $(STAMP) $(DEMO_STAMP)

# the demo needs the package alone (no test, video, cluster or Bullet extras: 16 s less), and
# no bytecode compiled ahead for every module of its dependencies: Python compiles those it
# imports as it imports them (measured from the pip cache on a loaded 2-core machine: the
# install 43 CPU-s instead of 82-89, the demo's imports 13.5 CPU-s once instead of 4.6)
DEMO_STAMP := $(VENV)/.demo-stamp
$(DEMO_STAMP): pyproject.toml setup.py
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-compile -e .
	touch $(DEMO_STAMP)

DOCS_STAMP := $(VENV)/.docs-stamp
$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[dev,video,slurm,docs]"
	touch $(DOCS_STAMP)

demo: $(DEMO_STAMP)
	$(BIN)/spine-mj validate --quick --out $(DEMO_OUT)

# a test that crashes its worker fails once; a replacement worker would run it again
test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --max-worker-restart=0 -m "not docs"

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# make bench: results in benchmarks/out/ (untracked), each missed target marked;
# make bench BENCH_ARGS="--update --readme": the committed results and README section rewritten
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py $(BENCH_ARGS)

# Build the wheel, install it (not editable) into a fresh venv and use it from a folder
# outside the repository: presets, the MuJoCo rig and the README's examples (example:NAME,
# shipped scans and sweep configs) must come from the installed package.
wheel-check: $(STAMP)
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(BIN)/python -m pip wheel --quiet --no-deps --wheel-dir "$$tmp/dist" . ; rm -rf build; \
	$(PYTHON) -m venv "$$tmp/venv"; \
	"$$tmp/venv/bin/python" -m pip install --quiet "$$tmp"/dist/spine_mj-*.whl; \
	mkdir "$$tmp/run"; cd "$$tmp/run"; \
	"$$tmp/venv/bin/spine-mj" surface list; \
	"$$tmp/venv/bin/python" -c "import spine_mj.presets as p; p.make_surface('paper-single-peak')"; \
	"$$tmp/venv/bin/python" -c "import mujoco; from spine_mj.resources import model_path; \
	m = mujoco.MjModel.from_xml_path(str(model_path())); print('rig compiles:', model_path(), m.nbody, 'bodies')"; \
	"$$tmp/venv/bin/spine-mj" simulate paper-single-peak --start -3,-1 --duration 0.05 --resolution 41 --out sim; \
	"$$tmp/venv/bin/spine-mj" reproduce single-peak --quick --out repro; \
	"$$tmp/venv/bin/spine-mj" examples; \
	"$$tmp/venv/bin/spine-mj" surface make paper-fractal --hurst 0.7 --seed 3 -o fractal.npz --png fractal.png; \
	"$$tmp/venv/bin/spine-mj" surface make --from-file example:plu-1.plu --fill harmonic --spacing 2e-6 -o scan.npz; \
	"$$tmp/venv/bin/spine-mj" surface show scan.npz -o scan.png; \
	"$$tmp/venv/bin/spine-mj" surface info example:plu-1.plu -o psd.png; \
	"$$tmp/venv/bin/python" -c "from spine_mj import examples, sweep; \
	[sweep.load_config(examples.resolve('example:' + n)) for n, (k, _) in examples.list_examples().items() if k == 'sweep']; \
	print('every shipped sweep config reads, its example scans found')"; \
	"$$tmp/venv/bin/spine-mj" sweep example:paper-quasistatic.toml --out runs/qs --quiet; \
	echo "wheel-check: OK"

# The site: README's headline table regenerated from the committed validation.json, then
# Sphinx with warnings as errors (the gallery's scripts run, the results pages are written
# from analysis/reports/). Output: docs/_build/html/index.html
docs: $(DOCS_STAMP)
	$(BIN)/python docs/tools/readme_table.py
	$(BIN)/sphinx-build -W --keep-going -q -b html docs docs/_build/html
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m docs tests/docs

clean: clean-cache
	rm -rf $(VENV) $(DEMO_OUT) .pytest_cache .ruff_cache build docs/_build

# numba's kernel caches (docs/user_guide/performance.md: a kernel that compiles in another
# file's kernels is not recompiled when only that file changes)
clean-cache:
	find spine_mj -name '*.nbi' -delete -o -name '*.nbc' -delete
