#!/usr/bin/env bash
# The tests, Rust and Python: `cargo test --workspace` (without building the examples, which
# `cargo clippy --all-targets` checks), then the Python package built from this
# checkout into a fresh virtual environment (maturin, through pip) and its pytest suite.
#
# Needs a Rust toolchain, Python 3.10 or newer with pip and venv (PYTHON names another than
# python3), and the package registries. The environment is made in target/python-venv, or in
# CHETAEV_VENV; nothing is installed outside it.
set -euo pipefail
cd "$(dirname "$0")/.."
# One clean build, as from a fresh clone: incremental caches would cost time and disk (several GB)
# for a build made once. Set CARGO_INCREMENTAL=1 to keep them.
export CARGO_INCREMENTAL=${CARGO_INCREMENTAL:-0}

cargo test --workspace --lib --bins --tests
# The same packages as above (the Python package's crate has no doc tests: its docs are Python), so that
# the dependencies are built with the same features and not again.
cargo test --workspace --doc

python=${PYTHON:-python3}
venv=${CHETAEV_VENV:-target/python-venv}
rm -rf "$venv"
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip
# The package and its test extras (pytest, matplotlib, scipy), as a user installs it, but built in
# the test profile (`maturin develop`'s default) rather than optimised: debug assertions and
# overflow checks on. With the crate's feature `workspace-features` its dependencies have the
# features of the Rust tests' build above, which is reused rather than made again (Cranelift's
# among them); the package itself is the same.
MATURIN_PEP517_ARGS="--profile dev --features workspace-features" \
    "$venv/bin/python" -m pip install --quiet "./crates/chetaev-py[test]"
# From the tests' folder, so that `import chetaev` finds the installed package, not the sources.
cd crates/chetaev-py
"../../$venv/bin/python" -m pytest -q -p no:cacheprovider tests
