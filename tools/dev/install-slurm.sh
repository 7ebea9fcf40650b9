#!/usr/bin/env bash
# Installs Slurm and munge from Debian for the cluster test (tests/slurm.rs), which starts
# its own throwaway single-node cluster with tools/user/slurm/local-cluster.sh. The packages'
# own services are not used. Idempotent.
set -euo pipefail
packages=(slurmctld slurmd slurm-client munge)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO=sudo
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
# munged refuses to start without a key; the package makes one, but not on every system.
if [ ! -s /etc/munge/munge.key ]; then
  $SUDO mungekey --create --keyfile=/etc/munge/munge.key
fi
