#!/usr/bin/env bash
# Checks out the base revision beside this checkout (../chetaev-baseline) and gives its chetaev a
# version of its own (and so the workspace crates it depends on), so both revisions can be linked
# into one binary.
set -euo pipefail
rev=${1:?usage: prepare.sh <base revision>}
top=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
dest="$top/../chetaev-baseline"
if [ ! -d "$dest" ]; then
  git -C "$top" worktree add --detach "$dest" "$rev"
fi
# chetaev and the workspace crates it depends on (those the base revision has).
for krate in chetaev chetaev-native; do
  if [ -f "$dest/crates/$krate/Cargo.toml" ]; then
    sed -i 's/^version.workspace = true/version = "0.0.0-base"/' "$dest/crates/$krate/Cargo.toml"
  fi
done
echo "base revision $rev in $dest"
