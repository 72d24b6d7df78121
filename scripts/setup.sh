#!/usr/bin/env bash
# Installs every Debian 12 package hiltwin needs to build, test and benchmark.
# Fast when everything is present (one dpkg-query, no network); uses sudo when not root;
# stops with a clear message when a package cannot be had.
set -euo pipefail

packages=(
  cmake g++ make pkg-config git                 # toolchain
  libeigen3-dev                                 # model state (fixed-size Eigen)
  libboost-dev                                  # Boost.Odeint reference simulation
  libspdlog-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev
  libfftw3-dev                                  # Welch spectra in `hiltwin assess`
  liblttng-ust-dev lttng-tools babeltrace2      # tracepoints and trace tests
  liblttng-ctl-dev libbabeltrace2-dev           # `hiltwin trace`: sessions, reading CTF
  libtracefs-dev libtraceevent-dev              # `hiltwin trace --kernel`: scheduler events
  libgtest-dev libgmock-dev                     # tests
  rt-tests valgrind bc                          # cyclictest peer, callgrind counts, bench arithmetic
  clang-tidy                                    # scripts/tidy.sh: the function-size rule
  gnuplot-nox                                   # `hiltwin assess --plot`
  cyclonedds-dev cyclonedds-tools               # telemetry over DDS (idlc generates the types)
  libcpp-httplib-dev                            # the live web page (--web)
  chromium                                      # the web page test (headless)
  libzip-dev libxml2-dev                        # FMI 2.0 FMUs: unpacking, modelDescription.xml
  yosys nextpnr-ice40 fpga-icestorm verilator   # the IcoBoard gateware (fpga/, docs/fpga.md)
  clang libclang-rt-14-dev                      # libFuzzer targets (fuzz/; the runtime is only recommended)
  stress-ng                                     # the fault matrix's CPU hog (docs/reliability.md)
)

# One dpkg-query for all: names it does not know at all are missing too.
installed=$(dpkg-query -W -f='${Package} ${Status}\n' "${packages[@]}" 2>/dev/null |
            awk '$4 == "installed" { print $1 }' || true)
missing=()
for p in "${packages[@]}"; do
  grep -qx "$p" <<<"$installed" || missing+=("$p")
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
  unavailable=()
  for p in "${missing[@]}"; do
    candidate=$(apt-cache policy "$p" 2>/dev/null | awk '/Candidate:/ { print $2 }')
    [[ -n "$candidate" && "$candidate" != "(none)" ]] || unavailable+=("$p")
  done
  echo "setup: could not install: ${missing[*]}" >&2
  if ((${#unavailable[@]} > 0)); then
    echo "setup: no installable version of: ${unavailable[*]} (not in the configured apt sources)" >&2
  fi
  echo "setup: hiltwin needs Debian 12 (bookworm) with its main archive in /etc/apt/sources.list" >&2
  exit 1
fi
echo "setup: done"
