#!/usr/bin/env bash
# Installs every Debian 12 package hiltwin needs to build, test, benchmark and package.
# Fast when everything is present (one dpkg-query, no network); uses sudo when not root;
# stops with a clear message when a package cannot be had.
#   --cross arm64: also the arm64 cross build (docs/raspberry-pi.md): Debian's cross toolchain,
#   the arm64 libraries through multiarch and qemu-user-static, registered with the kernel's
#   binfmt_misc so that an arm64 test that starts an arm64 program runs it under qemu too.
set -euo pipefail

usage() {
  echo "usage: bash scripts/setup.sh [--cross arm64]"
  echo "  installs the Debian 12 packages hiltwin needs (with sudo when not root)"
  echo "  --cross arm64  also the arm64 cross toolchain, arm64 libraries and qemu (tests)"
}
cross=""
while (($# > 0)); do
  case $1 in
    --cross)
      [[ $# -ge 2 ]] || { echo "setup: --cross needs an architecture: arm64" >&2; exit 2; }
      [[ $2 == arm64 ]] || { echo "setup: --cross $2: only arm64 is supported" >&2; exit 2; }
      cross=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "setup: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done

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
  libjs-three                                   # three.js for the page's 3D view (embedded)
  chromium                                      # the web page test (headless)
  libzip-dev libxml2-dev                        # FMI 2.0 FMUs: unpacking, modelDescription.xml
  libssl-dev                                    # SHA-256 of a controller's file (its report)
  yosys nextpnr-ice40 fpga-icestorm verilator   # the IcoBoard gateware (board/fpga/, docs/fpga.md)
  clang libclang-rt-14-dev                      # libFuzzer targets (fuzz/; the runtime is only recommended)
  stress-ng                                     # the fault matrix's CPU hog (docs/reliability.md)
  dpkg-dev fakeroot file                        # CPack's .deb: dpkg-shlibdeps, file ownership
  help2man groff-base                           # the man page from --help, and its render test
  ccache                                        # the four builds of scripts/test.sh share one cache
  lld                                           # links 3x faster than GNU ld (CMakeLists.txt)
  parallel libxml2-utils                        # `hiltwin test`'s tests: shards through GNU parallel, JUnit checked by xmllint
)

# The arm64 cross build: the libraries hiltwin links, as arm64 multiarch packages beside the
# host's (the architecture-independent ones, Eigen, CLI11, nlohmann-json, are shared).
cross_packages=(
  crossbuild-essential-arm64 qemu-user-static
  libboost-dev:arm64 libspdlog-dev:arm64 libfmt-dev:arm64 libtomlplusplus-dev:arm64
  libfftw3-dev:arm64 liblttng-ust-dev:arm64 liblttng-ctl-dev:arm64 libbabeltrace2-dev:arm64
  libtracefs-dev:arm64 libtraceevent-dev:arm64 libgtest-dev:arm64 libgmock-dev:arm64
  cyclonedds-dev:arm64 libcpp-httplib-dev:arm64 libzip-dev:arm64 libxml2-dev:arm64
  libssl-dev:arm64
)

if [[ $(id -u) -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null; then
  sudo=(sudo)
else
  sudo=(false)  # only used when something is missing; reported below
fi

# qemu-user-static's own registration needs systemd-binfmt, which a container does not run:
# mount binfmt_misc when it is not mounted and register the arm64 handler from Debian's file.
register_qemu_binfmt() {
  local fs=/proc/sys/fs/binfmt_misc
  [[ -e $fs/qemu-aarch64 ]] && return 0
  if [[ ! -e $fs/register ]]; then
    "${sudo[@]}" mount -t binfmt_misc binfmt_misc "$fs" 2>/dev/null || true
  fi
  if [[ ! -e $fs/register ]]; then
    echo "setup: cannot mount binfmt_misc at $fs: arm64 test programs cannot start each other" >&2
    echo "setup: as root: mount -t binfmt_misc binfmt_misc $fs" >&2
    exit 1
  fi
  if ! "${sudo[@]}" sh -c "cat /usr/lib/binfmt.d/qemu-aarch64.conf > $fs/register"; then
    echo "setup: could not register qemu-aarch64 with binfmt_misc ($fs/register)" >&2
    exit 1
  fi
  echo "setup: registered qemu-aarch64 with binfmt_misc"
}

if [[ -n $cross ]]; then
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then
    echo "setup: adding the arm64 architecture (dpkg --add-architecture arm64)"
    "${sudo[@]}" dpkg --add-architecture arm64
  fi
  packages+=("${cross_packages[@]}")
fi

# One dpkg-query for all: names it does not know at all are missing too. Each installed package
# is listed as name:arch; a name asked without an architecture is the host's (or "all").
host_arch=$(dpkg --print-architecture)
installed=$(dpkg-query -W -f='${Package}:${Architecture} ${Status}\n' "${packages[@]}" \
              2>/dev/null | awk '$4 == "installed" { print $1 }' || true)
missing=()
for p in "${packages[@]}"; do
  if [[ $p == *:* ]]; then
    grep -qxF "$p" <<<"$installed" || missing+=("$p")
  else
    grep -qxF -e "$p:$host_arch" -e "$p:all" <<<"$installed" || missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  [[ -z $cross ]] || register_qemu_binfmt
  exit 0
fi

if [[ ${sudo[0]:-} == false ]]; then
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
[[ -z $cross ]] || register_qemu_binfmt
echo "setup: done"
