#!/bin/sh
# Builds the single header phgmg.h from the fragments in dev/ (declarations
# h*.h in order, then implementations i*.c in order). Atomic: writes a
# temporary file and renames it, so concurrent builds never see half a header.
set -e
cd "$(dirname "$0")/.."
out=phgmg.h
tmp=$(mktemp phgmg.h.XXXXXX)
{
  cat dev/h00_manual.h
  echo '#ifndef PHGMG_H_INCLUDED'
  echo '#define PHGMG_H_INCLUDED'
  for f in dev/h[1-9]*.h; do cat "$f"; done
  echo '#endif /* PHGMG_H_INCLUDED */'
  echo
  echo '/* ======================================================================== */'
  echo '/*                              IMPLEMENTATION                              */'
  echo '/* ======================================================================== */'
  echo '#ifdef PHGMG_IMPLEMENTATION'
  echo '#ifndef PHGMG_IMPLEMENTATION_DONE'
  echo '#define PHGMG_IMPLEMENTATION_DONE'
  for f in dev/i[1-9]*.c; do cat "$f"; done
  echo '#endif /* PHGMG_IMPLEMENTATION_DONE */'
  echo '#endif /* PHGMG_IMPLEMENTATION */'
  cat dev/z99_license.h
} > "$tmp"
mv "$tmp" "$out"
