#!/usr/bin/env bash
# One-step set-up on a fresh Debian machine with Python 3.11:
# Debian libraries the wheels need, then this package (editable) with its Python dependencies.
#   ./install.sh          run-time set-up
#   ./install.sh --test   run-time set-up plus the test tools
set -euo pipefail
cd "$(dirname "$0")"
# libusb/libgl/libgomp/libx*: open3d, vtk (pyvista), numba; pango/harfbuzz/fonts: WeasyPrint's PDF reports
DEBIAN_PACKAGES="libusb-1.0-0 libgl1 libgomp1 libxrender1 libx11-6 libpango-1.0-0 libpangoft2-1.0-0 libharfbuzz-subset0 fonts-dejavu-core"
missing=""
for p in $DEBIAN_PACKAGES; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing
fi
extra=""
[ "${1:-}" = "--test" ] && extra="[test]"
python3 -m pip install -q --disable-pip-version-check -e ".${extra}"
