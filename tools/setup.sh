#!/usr/bin/env bash
# Set up rftstatic on a fresh Debian machine: SuiteSparse headers, OpenBLAS and chromium (when root), then the
# package with CHOLMOD, numba, the test tools and the documentation tools (Sphinx). Safe to run again: it
# skips what is already there.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  if ! dpkg -s libsuitesparse-dev libopenblas0-pthread >/dev/null 2>&1; then
    echo "setup: installing libsuitesparse-dev (CHOLMOD headers) and OpenBLAS with apt-get" >&2
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libsuitesparse-dev libopenblas0-pthread >/dev/null
  fi
  # headless Chromium renders view.html in the viewer's test (skipped without it); a setup without it still works
  if ! command -v chromium >/dev/null 2>&1; then
    echo "setup: installing chromium (the viewer's browser test) with apt-get" >&2
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; } ||
      echo "setup: chromium could not be installed; the viewer's browser test will be skipped" >&2
  fi
fi
if ! "$PY" -m pip install -q -e ".[cholmod,fast,test,docs]"; then
  echo "setup: scikit-sparse (CHOLMOD) did not build; installing without it (scipy's solver is used)" >&2
  "$PY" -m pip install -q -e ".[fast,test,docs]" || "$PY" -m pip install -q -e ".[test,docs]"
fi
