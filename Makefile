# Two entry points: `make demo` and `make test`. Both create .venv when missing.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
DEMO_OUT ?= demo-out

.PHONY: demo test lint bench wheel-check clean

$(STAMP): pyproject.toml setup.py
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev,video,slurm]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/spine-mj validate --quick --out $(DEMO_OUT)

# a test that crashes its worker fails once; a replacement worker would run it again
test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --max-worker-restart=0

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# make bench: results in benchmarks/out/ (untracked), each missed target marked;
# make bench BENCH_ARGS="--update --readme": the committed results and README section rewritten
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py $(BENCH_ARGS)

# Build the wheel, install it (not editable) into a fresh venv and use it from a folder
# outside the repository: presets and the MuJoCo rig must come from the installed package.
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
	echo "wheel-check: OK"

clean:
	rm -rf $(VENV) $(DEMO_OUT) .pytest_cache .ruff_cache build
