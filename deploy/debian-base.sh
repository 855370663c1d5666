#!/usr/bin/env bash
# A Debian 12 base image built from Debian's archive alone (debootstrap, then podman import),
# for machines that reach the archive but no container registry. On a machine that reaches a
# registry the Containerfile's default base (debian:bookworm-slim) needs none of this.
#   bash deploy/debian-base.sh [IMAGE]      default IMAGE: localhost/qvr-debian:bookworm
set -euo pipefail
image=${1:-localhost/qvr-debian:bookworm}
mirror=${QVR_DEBIAN_MIRROR:-http://deb.debian.org/debian}
if podman image exists "$image"; then
    echo "deploy: $image exists"
    exit 0
fi
rootfs=$(mktemp -d /var/tmp/qvr-rootfs.XXXXXX)
trap 'rm -rf "$rootfs"' EXIT
debootstrap --variant=minbase bookworm "$rootfs" "$mirror"
# The image's apt reads the same archive, security updates included.
cat > "$rootfs/etc/apt/sources.list" <<LIST
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb ${mirror%/debian}/debian-security bookworm-security main
LIST
rm -rf "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/cache/apt/archives/*.deb
tar -C "$rootfs" -c . | podman import - "$image"
echo "deploy: built $image"
