#!/usr/bin/env bash
# One-step set-up on a fresh Debian 12 machine (or any Linux with CPython 3.11-3.13):
# the Debian libraries the wheels need, then a project virtual environment .venv/ with this
# package (editable) and its Python dependencies. Nothing is installed into the system Python
# (Debian's Python carries the PEP 668 "externally managed" marker).
#   ./install.sh          run-time set-up
#   ./install.sh --test   run-time set-up plus the test tools
# Environment: PYTHON (default python3) picks the interpreter; VENV (default .venv) the folder.
# Afterwards: .venv/bin/riskassess ..., .venv/bin/python -m pytest (or 'source .venv/bin/activate').
set -euo pipefail
cd "$(dirname "$0")"
PYTHON="${PYTHON:-python3}"
VENV="${VENV:-.venv}"

apt_install() {
  local SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@"
}

# libusb/libgl/libgomp/libx*: open3d, vtk (pyvista), numba; pango/harfbuzz/fonts: WeasyPrint's PDF reports
DEBIAN_PACKAGES="libusb-1.0-0 libgl1 libgomp1 libxrender1 libx11-6 libpango-1.0-0 libpangoft2-1.0-0 libharfbuzz-subset0 fonts-dejavu-core"
# chromium (--test only): the headless browser in which the tests open the offline viewer.html. The
# report's 3-D pictures need no GL library: they are drawn by matplotlib's software (Agg) renderer.
[ "${1:-}" = "--test" ] && DEBIAN_PACKAGES="$DEBIAN_PACKAGES chromium"
if command -v dpkg >/dev/null 2>&1; then
  missing=""
  for p in $DEBIAN_PACKAGES; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
  [ -n "$missing" ] && apt_install $missing
fi

version=$("$PYTHON" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
case "$version" in
  3.11|3.12|3.13) ;;
  *) echo "install.sh: $PYTHON is Python $version; this project needs 3.11, 3.12 or 3.13 (set PYTHON=...)" >&2; exit 2 ;;
esac

if [ ! -x "$VENV/bin/python" ]; then
  if [ -e "$VENV" ]; then
    echo "install.sh: $VENV exists but holds no Python; move it away or set VENV=..." >&2
    exit 2
  fi
  # Debian's Python has the venv module but not ensurepip until python3.X-venv is installed:
  # try, and install that package only when the first attempt fails.
  if ! "$PYTHON" -m venv "$VENV" >/dev/null 2>&1; then
    rm -rf "$VENV"  # the half-made folder of the failed attempt just above, nothing else
    command -v apt-get >/dev/null 2>&1 || { echo "install.sh: '$PYTHON -m venv' failed and apt-get is not available" >&2; exit 2; }
    apt_install "python${version}-venv"
    "$PYTHON" -m venv "$VENV"
  fi
fi

extra=""
[ "${1:-}" = "--test" ] && extra="[test]"
"$VENV/bin/python" -m pip install -q --disable-pip-version-check -e ".${extra}"
# numba compiles the kernels once per install and source version (riskassess/warmup.py): here, in two
# processes, rather than in the first run or in every test worker. A failure only costs that wait later.
"$VENV/bin/python" -m riskassess.warmup || echo "install.sh: the kernels' warm-up failed; the first run compiles them instead" >&2
echo "install.sh: ready in $VENV (Python $version); run .venv/bin/riskassess --help"
