#!/usr/bin/env bash
# A QGIS test leg in a Debian chroot: runs this repository's `make test` inside a chroot of another Debian
# release, so the plugin is tested on the QGIS, Python and NumPy that release ships.  Two legs use it:
#
#   make test-qgis340   LEG=qgis340 SUITE=trixie: QGIS 3.40, Python 3.13, NumPy 2.2 (Debian 13)
#   make test-qgis344   LEG=qgis344 SUITE=sid:    QGIS 3.44, Python 3.14, NumPy 2.4 (Debian unstable; the last
#                                                 Qt5 QGIS: what sid ships moves, the leg logs the versions)
#
# (the host leg, `make test`, is Debian 12: QGIS 3.22, Python 3.11, NumPy 1.24).
#
# The chroot is cached OUTSIDE the repository (CI clones afresh every run) at $QGIS_CHROOT (default
# /var/cache/archaeoortho/$SUITE) and rebuilt when missing or when its package list changed (debootstrap +
# apt-get: about 4-6 minutes).  Each run bind-mounts the repository and ../shared (read-only; the tests look for
# ../shared/data) at their own paths, plus /proc /dev /sys, and unmounts them on exit, also on failure.
# BUILD_ONLY=1 builds (or checks) the chroot and stops there: .ci/run starts both builds beside the host leg.
# Inside, `make test` keeps its venv, apt stamp and QGIS profile under build/$LEG/, apart from the host's .venv
# and build/; the plugin link build/qgis-plugins/archaeoortho is shared (same target).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
LEG=${LEG:?set LEG (qgis340, qgis344), as the Makefile does}
SUITE=${SUITE:?set SUITE (the Debian release: trixie, sid), as the Makefile does}
CHROOT=${QGIS_CHROOT:-/var/cache/archaeoortho/$SUITE}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
SHARED=$(dirname "$ROOT")/shared
PYTEST_ARGS=${PYTEST_ARGS:-}
: "${APT_PACKAGES:?set APT_PACKAGES to the apt list of the Makefile, as make test-qgis340 does}"

if [ "$(id -u)" != 0 ]; then
  exec sudo APT_PACKAGES="$APT_PACKAGES" PYTEST_ARGS="$PYTEST_ARGS" QGIS_CHROOT="$CHROOT" LEG="$LEG" BUILD_ONLY="${BUILD_ONLY:-0}" \
    SUITE="$SUITE" DEBIAN_MIRROR="$MIRROR" "${BASH_SOURCE[0]}" "$@"
fi

log() { echo "$LEG: $*" >&2; }

# Every mount point at or below $1, deepest first (read from /proc/self/mounts; octal escapes kept as is).
mounts_under() {
  awk -v d="$1" '$2 == d || index($2, d "/") == 1 { print $2 }' /proc/self/mounts | sort -r
}

unmount_all() {
  local m
  for m in $(mounts_under "$1"); do
    umount "$m" 2>/dev/null || umount -l "$m" || true
  done
  if [ -n "$(mounts_under "$1")" ]; then
    log "still mounted under $1:"; mounts_under "$1" >&2
    return 1
  fi
}

# Remove a chroot directory, but never while anything (the repository!) is still mounted inside it.
remove_tree() {
  [ -e "$1" ] || return 0
  unmount_all "$1" || { log "refusing to remove $1"; exit 1; }
  rm -rf --one-file-system "$1"
}

mount_system() {  # /proc /dev /sys into chroot $1
  mkdir -p "$1/proc" "$1/dev" "$1/sys"
  mount -t proc proc "$1/proc"
  mount --rbind /dev "$1/dev" && mount --make-rslave "$1/dev"
  mount --rbind /sys "$1/sys" && mount --make-rslave "$1/sys"
}

# The host's network settings and certificate authorities (a TLS-inspecting proxy's CA among them),
# so that apt and pip inside reach what they reach outside.
host_config() {  # into chroot $1
  cp -L /etc/resolv.conf "$1/etc/resolv.conf" 2>/dev/null || true
  mkdir -p "$1/usr/local/share/ca-certificates"
  if [ -d /usr/local/share/ca-certificates ]; then
    cp -rL /usr/local/share/ca-certificates/. "$1/usr/local/share/ca-certificates/"
  fi
  if [ -x "$1/usr/sbin/update-ca-certificates" ]; then
    chroot "$1" update-ca-certificates >/dev/null 2>&1 || log "warning: update-ca-certificates failed"
  fi
}

in_chroot() {  # chroot $1, command...: a clean environment plus the proxy/pip/TLS settings of this one
  local dir=$1; shift
  local pass=() v
  for v in http_proxy https_proxy no_proxy HTTP_PROXY HTTPS_PROXY NO_PROXY PIP_INDEX_URL PIP_EXTRA_INDEX_URL \
           PIP_DEFAULT_TIMEOUT PIP_DISABLE_PIP_VERSION_CHECK; do
    [ -n "${!v:-}" ] && pass+=("$v=${!v}")
  done
  chroot "$dir" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb DEBIAN_FRONTEND=noninteractive \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    SSL_CERT_FILE=/etc/ssl/certs/ca-certificates.crt REQUESTS_CA_BUNDLE=/etc/ssl/certs/ca-certificates.crt \
    PIP_CERT=/etc/ssl/certs/ca-certificates.crt "${pass[@]}" "$@"
}

# What the chroot must hold: the Makefile's apt list plus what running make in it needs.
WANT=$(printf '%s\n' $APT_PACKAGES make git ca-certificates | sort -u)
STAMP=.archaeoortho-packages

build_chroot() {
  local new=$CHROOT.new
  command -v debootstrap >/dev/null || { apt-get update -q && apt-get install -y -q debootstrap; } >&2
  remove_tree "$new"
  mkdir -p "$(dirname "$CHROOT")"
  log "debootstrap $SUITE into $new ($MIRROR)"
  debootstrap --variant=minbase "$SUITE" "$new" "$MIRROR" >"$CHROOT.debootstrap.log" 2>&1 \
    || { tail -20 "$CHROOT.debootstrap.log" >&2; remove_tree "$new"; exit 1; }
  host_config "$new"
  # A mirror may serve a frozen copy of a release whose Release file is past its Valid-Until date (sid's is
  # valid for a week): apt then refuses it as expired.  The packages are still checked against the signature.
  echo 'Acquire::Check-Valid-Until "false";' >"$new/etc/apt/apt.conf.d/99archaeoortho-valid-until"
  mount_system "$new"
  log "apt-get install: $(echo $WANT)"
  if ! { in_chroot "$new" apt-get update -q && \
         in_chroot "$new" apt-get install -y -q --no-install-recommends $WANT && \
         in_chroot "$new" apt-get clean; } >"$CHROOT.apt.log" 2>&1; then
    tail -30 "$CHROOT.apt.log" >&2; remove_tree "$new"; exit 1
  fi
  unmount_all "$new"
  host_config "$new"
  echo "$WANT" >"$new/$STAMP"
  remove_tree "$CHROOT"
  mv "$new" "$CHROOT"
}

mkdir -p "$(dirname "$CHROOT")"
exec 9>"$CHROOT.lock"
flock 9  # one leg at a time per chroot

cleanup() { unmount_all "$CHROOT" || true; unmount_all "$CHROOT.new" 2>/dev/null || true; }
trap cleanup EXIT
trap 'exit 130' INT TERM

start=$SECONDS
unmount_all "$CHROOT" 2>/dev/null || true  # left over from a killed run
if [ ! -f "$CHROOT/$STAMP" ] || [ "$(cat "$CHROOT/$STAMP")" != "$WANT" ]; then
  [ -d "$CHROOT" ] && log "package list changed (or chroot incomplete): rebuilding $CHROOT"
  build_chroot
  log "chroot built in $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s"
else
  log "reusing $CHROOT"
fi
if [ "${BUILD_ONLY:-0}" = 1 ]; then  # .ci/run builds missing chroots ahead, beside the host leg
  exit 0
fi

host_config "$CHROOT"
mount_system "$CHROOT"
# The repository and ../shared at the same paths as outside: absolute paths (the plugin link
# build/qgis-plugins/archaeoortho, which the tests use) mean the same thing on both legs.
mkdir -p "$CHROOT$ROOT" "$CHROOT$SHARED"
mount --bind "$ROOT" "$CHROOT$ROOT"
if [ -d "$SHARED" ]; then
  mount --bind "$SHARED" "$CHROOT$SHARED"
  mount -o remount,bind,ro "$CHROOT$SHARED"
else
  log "no $SHARED: the tests that need it are skipped"
fi

log "$(in_chroot "$CHROOT" sh -c 'echo QGIS $(dpkg-query -W -f "\${Version}" qgis), $(python3 -V), NumPy \
$(python3 -c "import numpy; print(numpy.__version__)")')"
test_start=$SECONDS
rc=0
in_chroot "$CHROOT" make -C "$ROOT" test VENV="$ROOT/build/$LEG/venv" BUILD="$ROOT/build/$LEG" \
  PLUGINS="$ROOT/build/qgis-plugins" PYTEST_ARGS="$PYTEST_ARGS" || rc=$?
log "make test ($LEG) exited $rc after $(( (SECONDS - test_start) / 60 )) min $(( (SECONDS - test_start) % 60 )) s;" \
  "whole leg $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s"
exit $rc
