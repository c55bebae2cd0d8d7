#!/usr/bin/env bash
# Sourced by bin/activeintent and bin/test: create .venv and install the project on first use.
# Re-installs only when pyproject.toml changes. llama-cpp-python is built from source the first
# time (about 10 minutes on 2 cores).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
PY="${PYTHON:-python3.11}"
command -v "$PY" >/dev/null 2>&1 || PY=python3

need_apt() {  # install Debian packages that are missing (root, or sudo when available)
  local missing=()
  for pkg in "$@"; do dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "activeintent: installing Debian packages: ${missing[*]}" >&2
  $sudo apt-get update -qq >&2
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
}

if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -c 'import sys; assert sys.version_info[:2] == (3, 11), "activeintent needs Python 3.11"'
  echo "activeintent: creating $VENV" >&2
  "$PY" -m venv "$VENV"
  "$VENV/bin/python" -m pip install -q --upgrade pip >&2
fi

EXTRAS="${ACTIVEINTENT_EXTRAS:-embedded}"  # the default run uses the embedded model
STAMP="$VENV/.installed-$(cat "$ROOT/pyproject.toml" | sha256sum | cut -c1-16)${EXTRAS:+-$EXTRAS}"
# The embedded model is built for one fixed instruction set (x86-64 with AVX2 and FMA), not for
# the building machine's CPU: llama.cpp's float results follow the kernels it was compiled with,
# and the committed naturalness table must replay on every machine. The wheel is kept in a
# folder named after these flags, so a wheel built natively elsewhere (pip's own cache does not
# key on CMAKE_ARGS) is never picked up instead.
LLAMA_SPEC="llama-cpp-python[server]>=0.3.8,<0.3.17"  # the same range as pyproject's "embedded"
LLAMA_CMAKE_ARGS="-DGGML_NATIVE=OFF -DGGML_AVX=ON -DGGML_AVX2=ON -DGGML_FMA=ON -DGGML_F16C=ON -DGGML_AVX512=OFF -DGGML_AVX_VNNI=OFF -DGGML_BMI2=OFF"
WHEELS="${XDG_CACHE_HOME:-$HOME/.cache}/activeintent/wheels/$(echo "$LLAMA_SPEC $LLAMA_CMAKE_ARGS" | sha256sum | cut -c1-12)"

if [ ! -f "$STAMP" ]; then
  echo "activeintent: installing the project into .venv (first run builds llama-cpp-python from source: ~10 min on 2 cores)" >&2
  export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}"
  if [[ ",$EXTRAS," == *",embedded,"* ]] && ! ls "$WHEELS"/llama_cpp_python-*.whl >/dev/null 2>&1; then
    echo "activeintent: building llama-cpp-python for x86-64 AVX2/FMA into $WHEELS" >&2
    CMAKE_ARGS="$LLAMA_CMAKE_ARGS" "$VENV/bin/python" -m pip wheel -q --no-deps --no-cache-dir \
      -w "$WHEELS" "$LLAMA_SPEC" >&2
  fi
  "$VENV/bin/python" -m pip install -q --find-links "$WHEELS" -e "$ROOT${EXTRAS:+[$EXTRAS]}" >&2
  touch "$STAMP"
fi
