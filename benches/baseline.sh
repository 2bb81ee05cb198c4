#!/usr/bin/env bash
# Issue 9's reference measurement: the Figure 3 main branch at N = 200 (every
# point with stability, link and self-distance; branch switching off) timed,
# in one run on one machine, with the first version that had continuation
# (session 1, commit 967699e, or the revision given as $1) and with this tree.
# Usage: benches/baseline.sh [REVISION]
set -euo pipefail
base_rev=${1:-967699e}
root=$(git rev-parse --show-toplevel)
work=$(mktemp -d)
trap 'git -C "$root" worktree remove --force "$work/base" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git -C "$root" worktree add --detach "$work/base" "$base_rev" >/dev/null 2>&1
(cd "$work/base" && cargo build --release --quiet)
(cd "$root" && cargo build --release --quiet)

# each version runs its own copy of the scene, main branch only
scene() { # tree out.toml eigenvalues
    sed -e 's/^switch_branches *=.*/switch_branches = false/' \
        -e "s/^eigenvalues *=.*/eigenvalues = $3/" \
        -e "s|^json *=.*|json = \"$work/$(basename "$2" .toml).json\"|" \
        "$1/scenes/fig3_kirchhoff.toml" >"$2"
}
scene "$work/base" "$work/base.toml" 2
scene "$root" "$work/now_eigen.toml" 2
scene "$root" "$work/now_inertia.toml" 0

seconds() { # binary scene
    local t0 t1
    t0=$(date +%s.%N)
    "$1" run "$2" --segments 200 --no-record >/dev/null 2>&1
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc -l
}
b=$(seconds "$work/base/target/release/knotrod" "$work/base.toml")
e=$(seconds "$root/target/release/knotrod" "$work/now_eigen.toml")
i=$(seconds "$root/target/release/knotrod" "$work/now_inertia.toml")
printf '| version | stability per point | seconds | speed-up |\n|---|---|---|---|\n'
printf '| %s (baseline) | 2 eigenvalues + 2 frequencies | %.2f | 1.0× |\n' "$base_rev" "$b"
printf '| %s | 2 eigenvalues + 2 frequencies | %.2f | %.1f× |\n' "$(git -C "$root" rev-parse --short HEAD)" "$e" "$(echo "$b / $e" | bc -l)"
printf '| %s | inertia only (eigenvalues = 0) | %.2f | %.1f× |\n' "$(git -C "$root" rev-parse --short HEAD)" "$i" "$(echo "$b / $i" | bc -l)"
