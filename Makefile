# The two commands of the README: `make reproduce` (the main job) and `make test` (every test).
# One build profile (dev, with the numeric crates optimised: see Cargo.toml) serves both.

CARGO ?= cargo
LEARN := target/debug/learn
QUIET := $(if $(CI),--quiet,)

.PHONY: all data build test reproduce check-paper bench mismatch-demo lint fmt clean-results

all: build

data:
	@scripts/fetch-data.sh

build:
	$(CARGO) build --workspace --bins

test: data
	$(CARGO) test --workspace

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

fmt:
	$(CARGO) fmt --all
