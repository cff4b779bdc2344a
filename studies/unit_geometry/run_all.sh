#!/bin/bash
# Every run of the unit-geometry study, one FE process at a time, single-threaded.
# Usage (from this folder):  ./run_all.sh [final|screen|2d|mesh|all]   (default: all)
# Results: results/<name>.json (+ .npz with the final displacement field) and logs/<name>.log
set -u
cd "$(dirname "$0")"
PY=${PY:-../../.venv/bin/python}  # the repository's venv (README quick start)
export OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
mkdir -p results logs
run() {  # name, args...
  local name=$1; shift
  echo "== $name: python solve.py $*"
  $PY -u solve.py "$@" --out results/$name.json --save-u > logs/$name.log 2>&1
  grep RESULT logs/$name.log
}
what=${1:-all}
CAND="--cavity-height 6 --end-wall 3"
if [[ $what == final || $what == all ]]; then
  run final3d_all0 --dim 3 --orientation 000000000000000 $CAND
  run final3d_all1 --dim 3 --orientation 111111111111111 $CAND
fi
if [[ $what == 2d || $what == all ]]; then
  # 2D plane strain, no filler: far too compliant (no side walls), shown once
  run final2d_all0 --dim 2 --orientation 000000000000000 $CAND
  # 2D with the dissertation's filler E(P) of Eq 5.2 (fitted to the dissertation's unit)
  run final2d_all0_filler --dim 2 --orientation 000000000000000 $CAND --filler
  run final2d_all1_filler --dim 2 --orientation 111111111111111 $CAND --filler
  run final2d_all0_filler_h075 --dim 2 --orientation 000000000000000 $CAND --filler --element-size 0.75
fi
if [[ $what == screen || $what == all ]]; then
  # 3 units, 3D hex20 half model, base clamped, Ogden; end wall 1.5 -> cavity 7.5 mm long
  run s_closed_hc12 --dim 3 --units 3 --cavity-height 12 --end-wall 1.5
  run s_closed_hc9 --dim 3 --units 3 --cavity-height 9 --end-wall 1.5
  run s_closed_hc7.5 --dim 3 --units 3 --cavity-height 7.5 --end-wall 1.5
  run s_closed_hc7.5_cap --dim 3 --units 3 --cavity-height 7.5 --end-wall 1.5 --tip-cap 3
  run s_closed_hc6_cap --dim 3 --units 3 --cavity-height 6 --end-wall 1.5 --tip-cap 3
  run s_closed_hc4.5_cap --dim 3 --units 3 --cavity-height 4.5 --end-wall 1.5 --tip-cap 3
  run s_slit_medium_hc12 --dim 3 --units 3 --cavity-height 12 --end-wall 1.5 \
      --slit-width 1.5 --slit-depth 13.5 --medium 0.002
  run s_lc4.5_hc4.5 --dim 3 --units 3 --cavity-height 4.5 --end-wall 3
  run s_lc4.5_hc6 --dim 3 --units 3 $CAND
  run s_lc4.5_hc7.5 --dim 3 --units 3 --cavity-height 7.5 --end-wall 3
fi
if [[ $what == mesh || $what == all ]]; then
  run s_lc4.5_hc6_h075 --dim 3 --units 3 $CAND --element-size 0.75
fi
