#!/bin/sh
# test_lowrank_dae.sh — reduce --method bt (low-rank, sparse) on descriptor
# models through the command line, against an independent dense computation
# (NumPy/SciPy): tests/check_lowrank_dae.py (what it checks is described
# there) on an index-one RLC grid (algebraic constraints, with and without a
# port on a constraint) and a P1 acoustic model with a consistent mass matrix.
# Usage: sh tests/test_lowrank_dae.sh build/phgmg      (from the repository root)
# Needs NumPy and SciPy in /usr/bin/python3 (skipped with a note otherwise).
set -u
P=${1:-build/phgmg}
case "$P" in /*) ;; *) P="$PWD/$P" ;; esac
PY=/usr/bin/python3
ROOT=$PWD
T=$(mktemp -d "${TMPDIR:-/tmp}/phgmg_lowrank_dae.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
[ -x "$P" ] || { echo "test_lowrank_dae: $P is not an executable (build it first)"; exit 1; }
if ! "$PY" -c 'import numpy, scipy' 2>/dev/null; then
  echo "test_lowrank_dae: skipped ($PY has no NumPy/SciPy)"
  exit 0
fi
if "$PY" "$ROOT/tests/check_lowrank_dae.py" "$P" "$T" > "$T/check.txt" 2>&1; then
  cat "$T/check.txt"
  echo "test_lowrank_dae: all passed"
else
  cat "$T/check.txt"
  echo "test_lowrank_dae: failed"
  exit 1
fi
