# The two commands of the README: `make reproduce` (the main job) and `make test` (every test).
# Each does its own set-up (the flight data linked or fetched, the build), so either can be the first
# command on a fresh clone; crates/cli/tests/repository.rs checks the graph. One build profile
# (dev, with the numeric crates optimised: see Cargo.toml) serves both.

CARGO ?= cargo
LEARN := target/debug/learn
QUIET := $(if $(CI),--quiet,)

# A CI run builds a fresh clone once, where incremental compilation only writes its cache: without
# it the clean build took 8 min 40 s against 10 min on 2 cores. Kept elsewhere, where edits rebuild
# (every cargo call of one run must agree: switching it rebuilds the workspace).
ifdef CI
export CARGO_INCREMENTAL ?= 0
endif

.PHONY: all data build test reproduce ablations check-paper bench mismatch-demo own-data-example lint fmt clean-results

all: build

data:
	@scripts/fetch-data.sh

# Libraries (the Python extension crates/python among them), binaries, tests and examples in one
# build: with dev-dependencies in the same feature resolution,
# `cargo test` then reuses every artifact (building the binaries alone resolves features differently
# and recompiles faer, minutes on 2 cores).
build:
	$(CARGO) build --workspace --lib --bins --tests --examples

test: data build
	$(CARGO) test --workspace
	scripts/python-package.sh
	$(MAKE) check-paper

# The paper's tables and figures from one command (experiments/reproduce.json): results/,
# paper/tables/ and the README's tables block. Stage times are printed; see results/timings.json.
reproduce: data build
	$(LEARN) $(QUIET) reproduce --config experiments/reproduce.json --out results --latex-dir paper/tables --readme README.md --force

# Variants beyond the paper (experiments/variants.json): every variant on every cell over 5 seeds,
# model selection inside the support segment only; results/ablations/ablations.{md,json} and figures
# with the ensemble band. Takes about 6 minutes on 2 cores (LeARN meta-training for the learned-basis
# variants: three models per cell and seed for learn-ensemble3).
ablations: data build
	$(LEARN) $(QUIET) ablations --config experiments/variants.json --out results/ablations --force

# The regression against the paper: the same protocol and LeARN budget without the variant columns
# (experiments/ci.json), written to a git-ignored scratch directory, then compared with
# paper/published.json under the tolerances of paper/tolerances.json (non-zero exit on regression).
# The scratch is emptied first: files left there by an older tool have no output manifest, and a
# command never replaces files it did not write.
CI_RESULTS := results/.scratch/ci
check-paper: data build
	rm -rf $(CI_RESULTS)
	$(LEARN) $(QUIET) reproduce --config experiments/ci.json --out $(CI_RESULTS) --latex-dir $(CI_RESULTS)/latex --force
	$(LEARN) check-paper --results $(CI_RESULTS)/tables

# LeARN on your own data, the worked example (experiments/own-data/example.json): a simulated family
# of forced, damped Duffing oscillators written as CSV tasks to target/own-data-example (try the
# three commands of docs/own-data.md on them), meta-trained with the default settings, and the
# learning curve against SINDy and ridge: results/own-data/learning-curve.{svg,md,json}. About 25 s
# of processor time after the build (docs/own-data.md); not part of `make test`.
own-data-example: build
	$(LEARN) $(QUIET) own-data-example --config experiments/own-data/example.json --work target/own-data-example --out results/own-data --force

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

fmt:
	$(CARGO) fmt --all

# Speed against the Python references, in one run on this machine (needs `make data`; creates
# .venv through scripts/python-env.sh if missing). One command per line: other parts append theirs.
bench: data build
	scripts/bench/sindy.sh
	scripts/bench/learn.sh
	scripts/bench/scaling.sh
	scripts/bench/threads.sh
	scripts/bench/mismatch_length.sh
	scripts/bench/python_package.sh

# Sim-to-real mismatch: the tool blind on simulated flights with concealed effects (every case under
# every simulator/logger configuration of experiments/mismatch/demo.json: the matrix), then every
# real flight analysed together (one vehicle, one air velocity per flight; the known wind speeds only
# checked). Writes results/mismatch/{summary.md,summary.json,neural-fly.json,neural-fly.md,neural-fly.svg}.
# Takes about 10 minutes on 2 cores (the matrix about 6, the joint analysis about 4).
mismatch-demo: data build
	$(LEARN) mismatch --demo experiments/mismatch/demo.json --work target/mismatch-demo --out results/mismatch --force
	$(LEARN) mismatch --demo experiments/mismatch/demo-timing.json --work target/mismatch-demo-timing --out results/mismatch/timing --force
	$(LEARN) mismatch --demo experiments/mismatch/demo-vehicles.json --work target/mismatch-demo-vehicles --out results/mismatch/vehicles --force
	$(LEARN) mismatch --flights experiments/conditions.json --model experiments/mismatch/neural-fly.json --out results/mismatch --force
	$(LEARN) mismatch --recording data/crazyflie/randomwalk_l_cf102_01.csv --layout experiments/layouts/crazyflie-neural-swarm.json --model experiments/mismatch/vehicles/crazyflie-parrot.json --out results/mismatch/shared/crazyflie --force
	$(LEARN) mismatch --recording data/ulog/sample_px4_events.ulg --layout experiments/layouts/px4-ulog.json --model experiments/mismatch/vehicles/jmavsim-iris.json --half-width 0.4 --rows 186:262 --out results/mismatch/shared/jmavsim --force
	$(LEARN) mismatch --recording data/ulog/quadrotor_local.ulg --layout experiments/layouts/px4-ulog-thrust-setpoint.json --model experiments/mismatch/vehicles/px4-thrust-setpoint.json --half-width 0.4 --rows 0:720 --out results/mismatch/shared/quadrotor-local --force
