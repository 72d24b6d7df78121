#!/usr/bin/env bash
# Makes the Debian packages hiltwin (the command) and hiltwin-dev (headers, static libraries,
# CMake package) for amd64 or arm64 (cmake/HiltwinPackage.cmake): a release build in a folder of
# its own, without tests, benchmarks or gateware bitstreams, then cpack. Prints the .deb paths.
set -euo pipefail

usage() {
  cat <<'USAGE'
usage: bash scripts/package.sh [--arch amd64|arm64] [--output DIR] [--jobs N]
  builds hiltwin for release and makes hiltwin_<version>_<arch>.deb and
  hiltwin-dev_<version>_<arch>.deb
  --arch ARCH   amd64 or arm64; default: this machine's (dpkg --print-architecture). arm64 on
                an amd64 machine is a cross build: bash scripts/setup.sh --cross arm64 first
  --output DIR  where the .deb files go; default: <build folder>/packages
  --jobs N      parallel compile jobs; default: nproc
  build folder: build-package natively, build-package-<arch> when cross-compiling
USAGE
}

die() {
  echo "package: $*" >&2
  exit 2
}

root=$(cd "$(dirname "$0")/.." && pwd)
arch=""
output=""
jobs=$(nproc)
while (($# > 0)); do
  case $1 in
    --arch|--output|--jobs)
      [[ $# -ge 2 && -n $2 ]] || die "$1 needs a value (--help)"
      case $1 in
        --arch) arch=$2 ;;
        --output) output=$2 ;;
        --jobs) jobs=$2 ;;
      esac
      shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument '$1'" ;;
  esac
done

for tool in cmake cpack dpkg dpkg-architecture dpkg-shlibdeps; do
  command -v "$tool" >/dev/null ||
    die "$tool not found: run bash scripts/setup.sh (Debian: apt-get install cmake dpkg-dev)"
done
[[ $jobs =~ ^[1-9][0-9]*$ ]] || die "--jobs $jobs: give a positive whole number"

host_arch=$(dpkg --print-architecture)
arch=${arch:-$host_arch}
cmake_args=()
if [[ $arch == "$host_arch" ]]; then
  build_dir="$root/build-package"
elif [[ $arch == arm64 ]]; then
  toolchain="$root/cmake/toolchains/aarch64-linux-gnu.cmake"
  [[ -f $toolchain ]] || die "--arch arm64: the toolchain file $toolchain is missing"
  command -v aarch64-linux-gnu-g++ >/dev/null ||
    die "--arch arm64: no cross compiler aarch64-linux-gnu-g++;" \
        "run bash scripts/setup.sh --cross arm64"
  build_dir="$root/build-package-arm64"
  cmake_args+=(--toolchain "$toolchain")
else
  die "--arch $arch: this machine ($host_arch) builds $host_arch natively or arm64 by cross" \
      "compiling; use --arch $host_arch or --arch arm64"
fi
output=${output:-"$build_dir/packages"}
mkdir -p "$output" || die "--output $output: cannot create the folder"
output=$(cd "$output" && pwd)

# The code the test suite checks (RelWithDebInfo: -O2, NDEBUG) without the debug information.
# Libraries go to Debian's multiarch folder, which GNUInstallDirs picks only natively.
multiarch=$(dpkg-architecture -a "$arch" -qDEB_HOST_MULTIARCH 2>/dev/null) ||
  die "dpkg-architecture does not know $arch (Debian: apt-get install dpkg-dev)"
echo "package: configuring $build_dir ($arch)"
mkdir -p "$build_dir"
cmake -S "$root" -B "$build_dir" "${cmake_args[@]}" -DCMAKE_BUILD_TYPE=Release \
  "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG" "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
  -DCMAKE_INSTALL_PREFIX=/usr "-DCMAKE_INSTALL_LIBDIR=lib/$multiarch" \
  -DHILTWIN_BUILD_TESTS=OFF -DHILTWIN_BUILD_BENCH=OFF \
  -DHILTWIN_FPGA=OFF >"$build_dir/package-configure.log" 2>&1 ||
  { cat "$build_dir/package-configure.log" >&2; die "configuring $build_dir failed (above)"; }
echo "package: building with $jobs jobs"
cmake --build "$build_dir" -j "$jobs" || die "the build in $build_dir failed (above)"
# Cross-compiled, the man page and the completion script are made by the binary under qemu
# (cmake/GenerateManPage.cmake); without qemu the package goes without them, and says so.
if [[ $arch != "$host_arch" && ! -f $build_dir/hiltwin.bash ]]; then
  echo "package: no man page or bash completion in this $arch package (no qemu-aarch64 to run" \
       "the arm64 hiltwin: bash scripts/setup.sh --cross arm64)" >&2
fi

echo "package: cpack into $output"
log=$(cpack --config "$build_dir/CPackConfig.cmake" -G DEB -B "$output" 2>&1) ||
  { echo "$log" >&2; die "cpack failed (above); its work folder: $output/_CPack_Packages"; }
# cpack names each file it wrote: "CPack: - package: <path> generated."
debs=$(sed -n 's/^CPack: - package: \(.*\) generated\.$/\1/p' <<<"$log")
[[ -n $debs ]] || { echo "$log" >&2; die "cpack reported no package (above)"; }
echo "$debs"
