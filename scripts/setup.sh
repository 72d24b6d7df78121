#!/usr/bin/env bash
# Installs every Debian 12 package hiltwin needs to build, test and benchmark.
# Fast when everything is present (one dpkg query, no network); uses sudo when not root;
# stops with a clear message when a package cannot be had.
set -euo pipefail

packages=(
  cmake g++ make pkg-config git                 # toolchain
  libeigen3-dev                                 # model state (fixed-size Eigen)
  libboost-dev                                  # Boost.Odeint reference simulation
  libspdlog-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev
  libfftw3-dev                                  # Welch spectra in `hiltwin assess`
  liblttng-ust-dev lttng-tools babeltrace2      # tracepoints and trace tests
  libgtest-dev libgmock-dev libbenchmark-dev    # tests and benchmarks
  rt-tests valgrind bc                          # cyclictest peer, callgrind counts, bench arithmetic
  gnuplot-nox                                   # `hiltwin assess --plot`
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [[ $(id -u) -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null; then
  sudo=(sudo)
else
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: not root and no sudo: install them as root with apt-get install ${missing[*]}" >&2
  exit 1
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
if ! "${sudo[@]}" apt-get update -q; then
  echo "setup: apt-get update failed: check the network and /etc/apt/sources.list" >&2
  exit 1
fi
if ! "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"; then
  echo "setup: could not install: ${missing[*]}" >&2
  echo "setup: hiltwin needs Debian 12 (bookworm); check 'apt-cache policy <package>' for each" >&2
  exit 1
fi
echo "setup: done"
