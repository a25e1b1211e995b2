#!/bin/sh
# Installs what dicephys needs to build on Debian: Bullet's double-precision build
# (libbullet-dev, pkg-config name bullet-float64) and pkg-config. Does nothing if present.
set -e
if command -v pkg-config >/dev/null 2>&1 && pkg-config --exists bullet-float64; then
  exit 0
fi
SUDO=
[ "$(id -u)" -eq 0 ] || SUDO=sudo
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libbullet-dev pkg-config >/dev/null
