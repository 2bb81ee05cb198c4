#!/usr/bin/env bash
# Checks that `cargo build`, `cargo test` and the Python package ask the same
# features of every shared dependency (Cargo.toml's hand-unified features), so
# that each dependency is compiled once for all three. Prints the packages
# whose features differ and exits 1; prints nothing and exits 0 when they agree.
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tree() { # name, cargo tree arguments
    local name=$1
    shift
    cargo tree "$@" -f '{p} [{f}]' --prefix none --no-dedupe | sort -u >"$work/$name"
}
tree build -p knotrod -e normal,build
tree test -p knotrod -e normal,build,dev
tree python -p knotrod-python -e normal,build
# a package may appear twice in one tree (for the host and the target):
# compare each package's set of lines between the trees
awk '{ sub(/ \(.*\)/, ""); k = $1 " " $2; s[FILENAME, k] = s[FILENAME, k] "|" $0; keys[k]; files[FILENAME] }
     END { for (k in keys) { ref = ""
             for (f in files) if ((f, k) in s) {
               if (ref == "") ref = s[f, k]
               else if (s[f, k] != ref) { print "features differ: " k; break } } } }' \
    "$work"/* | sort >"$work/differ"
cat "$work/differ"
[ ! -s "$work/differ" ]
