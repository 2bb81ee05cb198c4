#!/usr/bin/env bash
# Peer measurements for docs/performance.md (issue 20): AUTO-07p and
# PyElastica on the paper's Appendix D knot. Installs what it needs
# (idempotent), runs each peer, prints markdown tables. See README.md.
#   RUNS=5 PYEL_RUNS=1 NTST="50 100 200" REF_NTST=400 PYEL_N="100 200" bash benches/peers/run.sh
set -euo pipefail
# AUTO-07p (Debian) is built with OpenMP: one thread unless asked otherwise
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
here="$(cd "$(dirname "$0")" && pwd)"
py="${PYTHON:-python3}"

need_apt=()
dpkg -s auto-07p >/dev/null 2>&1 || need_apt+=(auto-07p)
command -v gfortran >/dev/null 2>&1 || need_apt+=(gfortran)
command -v make >/dev/null 2>&1 || need_apt+=(make)
if ((${#need_apt[@]})); then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi
"$py" -c "import numpy, scipy" 2>/dev/null || "$py" -m pip install -q numpy scipy
if [ -n "${PYEL_N-100 200}" ]; then
  "$py" -c "import elastica" 2>/dev/null || "$py" -m pip install -q pyelastica
fi

echo "AUTO-07p $(dpkg-query -W -f='${Version}' auto-07p), $(gfortran --version | head -1)" >&2
"$py" -c "from importlib.metadata import version as v; print('PyElastica', v('pyelastica'))" >&2 2>/dev/null || true
# build rod.exe once (not timed) and warm numba's cache (not timed)
"$py" "$here/auto07p/run_auto.py" --ntst 50 --lean --dir "$here/auto07p/out/warm" >/dev/null
"$py" "$here/bench.py"
