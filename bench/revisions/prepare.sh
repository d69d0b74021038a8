#!/usr/bin/env bash
# Checks out the base revision beside this checkout (../chetaev-baseline) and gives its chetaev a
# version of its own, so both revisions can be linked into one binary.
set -euo pipefail
rev=${1:?usage: prepare.sh <base revision>}
top=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
dest="$top/../chetaev-baseline"
if [ ! -d "$dest" ]; then
  git -C "$top" worktree add --detach "$dest" "$rev"
fi
sed -i 's/^version.workspace = true/version = "0.0.0-base"/' "$dest/crates/chetaev/Cargo.toml"
echo "base revision $rev in $dest"
