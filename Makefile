# Set-up contract: on a fresh machine (Python 3.11 + pip), `make demo` and `make test` do everything.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.bidmp-installed

# OpenBLAS picks its kernels by the CPU it runs on (AVX-512 here, AVX2 on other machines), and
# their sums round differently: a near-tie in a committed table (9.03 mm at one nut or 9.04 at
# another) then flips from machine to machine. The tests and the committed results use the AVX2
# kernels on every x86-64 machine (set OPENBLAS_CORETYPE yourself to override).
ifeq ($(shell uname -m),x86_64)
export OPENBLAS_CORETYPE ?= Haswell
endif

.PHONY: demo test lint docs bench bench-smoke install clean readme fuzz mutation sim engines lasa random-cells routes user-cell avoidance view-check franka franka-check franka-agreement clfd mp-pytorch bench-prodmp clfd-capacity results-check

# (Re)create the virtual environment and install bidmp (editable) with pinned dependencies. An
# editable install does not rebuild the compiled loops when their source changes: this does.
$(STAMP): pyproject.toml constraints.txt setup.py src/bidmp/_kernels.pyx
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[collision,sim,mujoco,plan,ros,view,benchmark,test,bench,lint,docs]"
	# An editable install's bytecode is written at a module's first import, or never where
	# PYTHONDONTWRITEBYTECODE is set: then every command compiled bidmp's 120 modules again
	# (0.18 s of each). Compiled here once; a module edited since is compiled as it is imported.
	$(PY) -m compileall -q src/bidmp
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/bidmp demo

test: $(STAMP)
	$(PY) -m pytest -q -n 2

# The documentation site (mkdocs.yml: the guides, the architecture, the API reference from the
# docstrings) built with every warning an error, into site/.
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet

# ruff's linter (pycodestyle, pyflakes, import order, bugbear, pyupgrade, complexity, argument
# counts; settings in pyproject.toml) and its formatter, checked, over everything Python here.
lint: $(STAMP)
	$(VENV)/bin/ruff check src tests tools benchmarks
	$(VENV)/bin/ruff format --check src tests tools benchmarks

# The long campaign: the hypothesis suite of tests/test_fuzz.py x20 and the public-surface sweep of
# tests/test_fuzz_surface.py in full (every single change and 12 000 pairs); commits the outcome
# counts per entry point to docs/results/fuzz.json.
fuzz: $(STAMP)
	BIDMP_FUZZ=full $(PY) -m pytest -q tests/test_fuzz.py tests/test_fuzz_surface.py -p no:cacheprovider

# Mutation testing of the checks that guard the robot and judge success (tools/mutation.py): every
# small bug planted one at a time in the judging functions, the covering tests run against each;
# writes docs/mutation.md (score per area, every survivor killed or shown equivalent) and its
# outcomes docs/mutation.json. About 40 min on 2 cores. Then the compiled loops' planted bugs
# (tools/mutation_kernels.py, each built into a copy of the package): docs/mutation-kernels.md.
mutation: $(STAMP)
	$(PY) tools/mutation.py --workers 2
	$(PY) tools/mutation_kernels.py

# The whole nut task on the simulated Panda, open and closed loop, with pictures (bidmp-sim/ and
# bidmp-sim-closed-loop-hold/: a command's output folder is one run, so each has its own).
sim: $(STAMP)
	$(VENV)/bin/bidmp sim --out bidmp-sim
	$(VENV)/bin/bidmp sim --closed-loop --hold 2 3.5 0.5 --targets 12 --out bidmp-sim-closed-loop-hold

# The two physics engines checked against each other (tools/engines.py): every built-in arm's
# kinematics and inverse dynamics in PyBullet, MuJoCo and pinocchio; the built-in tasks and 20
# random users' cells simulated and jobbed on both engines (two processes); writes
# docs/results/engines.md. About an hour on 2 quiet cores.
engines: $(STAMP)
	$(PY) tools/engines.py --part models
	$(PY) tools/engines.py --part builtin & builtin=$$!; $(PY) tools/engines.py --part cells --cells 20 && wait $$builtin
	$(PY) tools/engines.py --part report

# The random-cell properties on 300 cells each (the tests draw 20-30): users' nut modules in mm, cm
# and m with posts, ducts and tilted brackets, the four arms, the bin either side, every target
# through evaluate, the simulator and the job and checked by closed-form geometry of the tests' own;
# the pad cells and the tilted pads of the evaluation.
random-cells: $(STAMP)
	BIDMP_RANDOM_CELLS=300 $(PY) -m pytest -q -n 2 tests/tasks/test_random_user_cells.py tests/tasks/test_random_cells.py tests/tasks/test_random_tilted_cells.py tests/tasks/test_tilted_user_cells.py

# The route property on 40 random users' cells (tests/sim/test_route_cells.py runs two targets of two
# cells): five arms (one from a URDF), mm/cm/m, posts by the elbow's path and between the columns,
# faces tilted 10-30 degrees, bins at the wrist's singularity; an oracle of the tests' own (plain
# RRT, 20x the pipeline's budget, its own IK and seed) decides which targets have a route, and every
# one that has must be solved in sim and job with no motion breaking the contract:
# docs/results/route_cells.md (exit 1 on a failure).
routes: $(STAMP)
	$(PY) tools/route_cells.py --cells 40 --workers 2

# The avoidance on 200 random fields at 1 kHz (the tests run 50 at 250 Hz), then the
# benchmark against movement_primitives on 50 fields: docs/results/avoidance.md, docs/avoidance.png.
avoidance: $(STAMP)
	BIDMP_AVOIDANCE_FIELDS=200 BIDMP_AVOIDANCE_RATE=1000 $(PY) -m pytest -q -n 2 tests/primitives/test_avoidance.py
	$(PY) benchmarks/bench_avoidance.py --fields 50 --out docs/results
	$(PY) tools/readme.py

# The full LASA benchmark (30 shapes x 7 demonstrations, every method) on the embedded Dask
# cluster, into bidmp-lasa/ (resumable: rerun to finish an interrupted sweep).
lasa: $(STAMP)
	$(VENV)/bin/bidmp benchmark lasa --resume --out bidmp-lasa
	cp bidmp-lasa/lasa.md bidmp-lasa/lasa.parquet docs/results/

bench: $(STAMP)
	$(PY) benchmarks/bench_dmp.py
	$(PY) benchmarks/bench_extension.py
	$(PY) benchmarks/bench_incremental.py
	$(PY) benchmarks/bench_scenario.py
	$(PY) benchmarks/bidmp_convergence.py
	$(PY) benchmarks/bench_timing.py
	$(PY) benchmarks/bench_sim.py
	$(PY) benchmarks/bench_cartesian.py
	$(PY) benchmarks/bench_lasa.py
	$(PY) benchmarks/bench_avoidance.py --fields 10
	$(PY) benchmarks/bench_job.py
	$(PY) benchmarks/bench_repair.py
	$(PY) benchmarks/bench_robustness.py
	$(PY) benchmarks/bench_verify.py
	$(PY) benchmarks/bench_startup.py
	$(PY) benchmarks/bench_rhythmic.py
	$(PY) benchmarks/bench_promp.py

# Every benchmark script once, quickly (one repetition, few fields, one LASA shape, the smoke
# modes): a CI stage, so that none breaks silently between full runs of make bench. Its timings
# are not the benchmarks' numbers.
bench-smoke: $(STAMP)
	cd benchmarks && ../$(PY) bench_dmp.py --repeats 1 --goals 50 > /dev/null
	cd benchmarks && ../$(PY) bench_extension.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_incremental.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_scenario.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bidmp_convergence.py > /dev/null
	cd benchmarks && ../$(PY) bench_timing.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_sim.py > /dev/null
	cd benchmarks && ../$(PY) bench_rhythmic.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_promp.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_cartesian.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_cold.py --rounds 1 > /dev/null
	cd benchmarks && ../$(PY) bench_lasa.py --every 20 --rounds 1 --shapes 1 --out ../.bench-smoke > /dev/null
	cd benchmarks && ../$(PY) bench_avoidance.py --fields 2 --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_job.py --repeats 1 > /dev/null
	cd benchmarks && ../$(PY) bench_repair.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_verify.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_robustness.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_startup.py --smoke > /dev/null
	cd benchmarks && ../$(PY) bench_threads.py --rounds 1 --load 0 > /dev/null
	cd benchmarks && ../$(PY) bench_clfd.py --tasks 2 --sides serial > /dev/null
	rm -rf .bench-smoke

# The 3-D viewer of a simulation run rendered in headless Chromium (Debian's package chromium:
# apt install chromium), offline, and its screenshot checked not to be blank (tools/view_check.py).
view-check: $(STAMP)
	rm -rf .view-check
	$(VENV)/bin/bidmp sim --view --targets 3,11 --no-pictures --out .view-check > /dev/null
	$(PY) tools/view_check.py .view-check/view.html --screenshot .view-check/view.png --expect-failing

# The paper's tables, the simulated nut task and the two built-in jobs (nuts, cells) regenerated
# and compared with the committed ones by value (about 35 s): a decimal may move in its last printed place or by a
# relative 1e-9, a count may not (tools/compare_results.py), so a faster equivalent computation
# can land. The whole runs are here, a CI stage, rather than in the suite (28 s of its 3 minutes).
# Each command writes its own folder (a command's output folder is one run); the tables are then
# gathered in .results-check/all.
results-check: $(STAMP)
	rm -rf .results-check
	mkdir -p .results-check/all
	$(VENV)/bin/bidmp reproduce table4 --out .results-check/table4 > /dev/null
	$(VENV)/bin/bidmp reproduce table5 --out .results-check/table5 > /dev/null
	$(VENV)/bin/bidmp reproduce figures --out .results-check/figures > /dev/null
	cp .results-check/table4/table4.md .results-check/table4/table4.json .results-check/table4/tasks.md .results-check/all/
	cp .results-check/table5/table5.md .results-check/table5/table5.json .results-check/all/
	cp .results-check/figures/figures.md .results-check/figures/figures.json .results-check/all/
	$(VENV)/bin/bidmp sim --no-pictures --out .results-check/sim > /dev/null
	cp .results-check/sim/sim.md .results-check/sim/sim_results.json .results-check/all/
	$(VENV)/bin/bidmp job --no-pictures --out .results-check/job > /dev/null
	$(VENV)/bin/bidmp job --scenario cell-removal --no-pictures --out .results-check/cells > /dev/null
	cp .results-check/job/job.md .results-check/job/job_results.json .results-check/all/
	cp .results-check/cells/job.md .results-check/all/job_cells.md
	cp .results-check/cells/job_results.json .results-check/all/job_cells_results.json
	$(PY) tools/compare_results.py .results-check/all docs/results
	rm -rf .results-check

# The acceptance's user cell, from one demonstration (tests/data/irb1200, tools/busbar_cell.py: an
# ABB IRB 1200 from its URDF in metres, no rest pose, 2 x 3 nuts on a 25 degree busbar plate behind
# a post, the bin at the wrist's singularity): bidmp demo, sim and job each exit 0 only when every
# target succeeds (about 1.5 min on 2 cores). A CI stage.
user-cell: $(STAMP)
	rm -rf .user-cell
	$(VENV)/bin/bidmp demo --scenario tests/data/irb1200/busbar.json --out .user-cell/demo > /dev/null
	$(VENV)/bin/bidmp sim --scenario tests/data/irb1200/busbar.json --no-pictures --out .user-cell/sim > /dev/null
	$(VENV)/bin/bidmp job --scenario tests/data/irb1200/busbar.json --no-pictures --out .user-cell/job > /dev/null
	rm -rf .user-cell

# Regenerate the committed result tables (docs/results/*.md) with the commands that make them,
# then copy them into README.md (tests/test_readme.py checks the two agree).
readme: $(STAMP)
	rm -rf .readme-out
	$(VENV)/bin/bidmp reproduce table4 --out .readme-out/table4 > /dev/null
	$(VENV)/bin/bidmp reproduce table5 --out .readme-out/table5 > /dev/null
	$(VENV)/bin/bidmp reproduce figures --out .readme-out/figures > /dev/null
	$(VENV)/bin/bidmp sim --out .readme-out/sim > /dev/null
	$(VENV)/bin/bidmp job --out .readme-out/job > /dev/null
	$(VENV)/bin/bidmp job --scenario cell-removal --no-pictures --out .readme-out/cells > /dev/null
	$(VENV)/bin/bidmp job --scenario nut-unscrewing-xarm6 --no-pictures --out .readme-out/xarm6 > /dev/null
	$(VENV)/bin/bidmp job --scenario nut-unscrewing-ur5 --no-pictures --out .readme-out/ur5 > /dev/null
	$(PY) tools/user_cells.py --out .readme-out/user_cells.md > /dev/null
	$(PY) tools/repair_order.py --out .readme-out/repair_order.md > /dev/null
	cp .readme-out/table4/table4.md .readme-out/table4/tasks.md .readme-out/table5/table5.md .readme-out/figures/figures.md .readme-out/sim/sim.md .readme-out/sim/sim_results.json docs/results/
	cp .readme-out/job/job.md .readme-out/job/job_results.json docs/results/
	cp .readme-out/cells/job.md docs/results/job_cells.md
	cp .readme-out/cells/job_results.json docs/results/job_cells_results.json
	cp .readme-out/xarm6/job.md docs/results/job_xarm6.md
	cp .readme-out/ur5/job.md docs/results/job_ur5.md
	cp .readme-out/user_cells.md .readme-out/repair_order.md docs/results/
	cp .readme-out/sim/sim_keyframes_bidmp.png docs/sim_keyframes_bidmp.png
	cp .readme-out/job/job_cycle.png docs/job_cycle.png
	rm -rf .readme-out
	$(PY) tools/recordings_figure.py
	$(PY) tools/robot_protocol.py > /dev/null
	$(PY) tools/readme.py

# Continual learning on the field's protocol (CLFD, Auddy et al.): the 26 LASA tasks and the 9
# RoboTasks9 pose tasks one after the other, every method, three seeds of the seeded ones, the
# cells on a 2-process Dask cluster: docs/results/clfd*.json, .md and their figures.
CLFD_METHODS = dmp-library,finetune,bidmp-library,promp-library,bidmp-continual
clfd: $(STAMP)
	rm -rf .clfd-out
	$(VENV)/bin/bidmp benchmark clfd --methods $(CLFD_METHODS) --seeds 3 --workers 2 --out .clfd-out/lasa
	$(VENV)/bin/bidmp benchmark clfd --dataset robottasks --methods $(CLFD_METHODS) --seeds 3 --workers 2 --out .clfd-out/robottasks
	cp .clfd-out/lasa/clfd.json .clfd-out/lasa/clfd.md .clfd-out/lasa/clfd_accuracy.png .clfd-out/lasa/clfd_dtw.png docs/results/
	cp .clfd-out/robottasks/clfd_robottasks.json .clfd-out/robottasks/clfd_robottasks.md .clfd-out/robottasks/clfd_robottasks_accuracy.png .clfd-out/robottasks/clfd_robottasks_dtw.png docs/results/
	rm -rf .clfd-out

# bidmp-continual's capacity on the same protocol's 26 LASA tasks: 8-64 enhancement nodes, three
# seeds each, against the plain library of the same start maps (ACC, BWT, mean DTW, how far each
# stored map is from its task's, every number kept), 25 cells on 2 Dask workers (about 10 min of
# CPU): docs/results/clfd_capacity.json, .md (copied into docs/guides/clfd.md) and .png.
clfd-capacity: $(STAMP)
	$(PY) tools/clfd_capacity.py --workers 2 --out docs/results > /dev/null
	$(PY) tools/readme.py

# The libfranka side environment: franka-sim (an FCI server simulating an FR3 in MuJoCo, motion
# limits enforced) and pylibfranka (the Franka client) at their pins in their own venv (they need
# NumPy 1.26), and an FR3 model built offline from the URDF franka-sim ships. 'bidmp verify
# --libfranka' finds it here (or by $$BIDMP_FRANKA_VENV) and starts and stops the server itself.
FRANKA_VENV  ?= .venv-franka
FRANKA_MODEL := $(FRANKA_VENV)/fr3_meshless.xml

$(FRANKA_MODEL): requirements-franka.txt src/bidmp/sim/_franka_side.py
	$(PYTHON) -m venv $(FRANKA_VENV)
	$(FRANKA_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(FRANKA_VENV)/bin/python -m pip install --quiet -r requirements-franka.txt
	$(FRANKA_VENV)/bin/python src/bidmp/sim/_franka_side.py build-model $(FRANKA_MODEL)

franka: $(FRANKA_MODEL) $(STAMP)
	BIDMP_FRANKA_VENV=$(FRANKA_VENV) $(VENV)/bin/bidmp verify --libfranka tests/data/fr3_quintic.csv

# CI's libfranka stage: the side environment, then a small set streamed through it (tests marked
# libfranka: a threshold pair of each limit kind, the job's motions on the FR3; the benchmark on
# one joint's five pairs), under 3 min.
franka-check: $(FRANKA_MODEL) $(STAMP)
	BIDMP_FRANKA_VENV=$(FRANKA_VENV) $(PY) -m pytest -q -p no:cacheprovider -m libfranka tests/sim/test_libfranka.py
	BIDMP_FRANKA_VENV=$(FRANKA_VENV) $(PY) benchmarks/bench_libfranka.py --per 1 --joints 3 > /dev/null

# bidmp's FCI judge against libfranka at the limits: 350 threshold-bisected streams, every limit
# kind on every joint (45 min on a 2-core machine at a load of 26-36): docs/results/libfranka.md.
franka-agreement: $(FRANKA_MODEL) $(STAMP)
	BIDMP_FRANKA_VENV=$(FRANKA_VENV) $(PY) benchmarks/bench_libfranka.py --out docs/results

# The peers' ProDMP (MP_PyTorch on torch's CPU build) in its own environment, beside bidmp: the
# benchmark's, never the suite's (torch is large). make bench-prodmp compares them in one run.
MPT_VENV ?= .venv-mpt
MPT_STAMP := $(MPT_VENV)/.installed

$(MPT_STAMP): requirements-mp-pytorch.txt pyproject.toml constraints.txt
	$(PYTHON) -m venv $(MPT_VENV)
	$(MPT_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(MPT_VENV)/bin/python -m pip install --quiet -r requirements-mp-pytorch.txt
	$(MPT_VENV)/bin/python -m pip install --quiet -c constraints.txt -e .
	touch $(MPT_STAMP)

mp-pytorch: $(MPT_STAMP)

bench-prodmp: $(MPT_STAMP)
	$(MPT_VENV)/bin/python benchmarks/bench_prodmp.py

clean:
	rm -rf $(VENV) $(FRANKA_VENV) $(MPT_VENV) site bidmp-out bidmp-sim bidmp-sim-closed-loop-hold bidmp-lasa .pytest_cache fuzz-report.json .view-check build
	rm -f src/bidmp/_kernels.c src/bidmp/_kernels.*.so
