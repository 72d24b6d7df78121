# Package.DebsInstallIntoAnEmptyRootAndRun (cmake -P; CMakeLists.txt here passes the -D values):
# the .deb packages of this build folder's CPack configuration (cmake/HiltwinPackage.cmake),
# their Depends checked against this machine's Debian packages, then both installed into an
# empty root with `dpkg --root` and the installed hiltwin run from there.
# In: BUILD_DIR, WORK_DIR, VERSION, CPACK_COMMAND; EMULATOR when cross-compiling.
cmake_minimum_required(VERSION 3.25)
include("${CMAKE_CURRENT_LIST_DIR}/test_steps.cmake")
hiltwin_test_require_vars(BUILD_DIR WORK_DIR VERSION CPACK_COMMAND)
foreach(tool dpkg dpkg-deb dpkg-query dpkg-shlibdeps)
  find_program(path_of_${tool} ${tool})
  if(NOT path_of_${tool})
    hiltwin_test_fail("packaging" WHY "${tool} is not installed"
                      HINT "apt-get install dpkg-dev (scripts/setup.sh installs it)")
  endif()
endforeach()

# The package names and architecture, as cpack will use them.
include("${BUILD_DIR}/CPackConfig.cmake")
set(arch "${CPACK_DEBIAN_PACKAGE_ARCHITECTURE}")
set(runtime_package "${CPACK_DEBIAN_RUNTIME_PACKAGE_NAME}")
set(dev_package "${CPACK_DEBIAN_DEV_PACKAGE_NAME}")

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
hiltwin_test_run("cpack" out
  COMMAND "${CPACK_COMMAND}" --config "${BUILD_DIR}/CPackConfig.cmake" -G DEB
          -B "${WORK_DIR}/debs"
  HINT "build the tree first (cmake --build ${BUILD_DIR}), then see "
       "cmake/HiltwinPackage.cmake")

# deb_field(<out> <deb> <field>): one control field of a .deb ("" when absent).
function(deb_field out deb field)
  execute_process(COMMAND dpkg-deb -f "${deb}" "${field}" OUTPUT_VARIABLE value
                  OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    hiltwin_test_fail("read ${deb}" WHY "dpkg-deb -f failed (exit ${code})"
                      HINT "cpack wrote something that is not a .deb: see its output")
  endif()
  set(${out} "${value}" PARENT_SCOPE)
endfunction()

file(GLOB debs "${WORK_DIR}/debs/*.deb")
foreach(deb IN LISTS debs)
  deb_field(name "${deb}" Package)
  set(deb_of_${name} "${deb}")
endforeach()
foreach(name "${runtime_package}" "${dev_package}")
  if(NOT deb_of_${name})
    hiltwin_test_fail("cpack" WHY "no ${name} package among: ${debs}"
                      HINT "see the components in cmake/HiltwinPackage.cmake")
  endif()
  deb_field(deb_arch "${deb_of_${name}}" Architecture)
  if(NOT deb_arch STREQUAL arch)
    hiltwin_test_fail("${name}" WHY "Architecture ${deb_arch}, the build is for ${arch}"
                      HINT "see hiltwin_debian_architecture in cmake/HiltwinPackage.cmake")
  endif()
endforeach()
set(runtime_deb "${deb_of_${runtime_package}}")
set(dev_deb "${deb_of_${dev_package}}")

execute_process(COMMAND dpkg --print-architecture OUTPUT_VARIABLE host_arch
                OUTPUT_STRIP_TRAILING_WHITESPACE)
# What satisfies a dependency of an ${arch} package here, one installed package a list item:
# "name provided, provided (= version), ...", with what it provides for the virtual names
# shlibs files use (libspdlog1.10 provides libspdlog1.10-fmt9). Natively: an ${arch} or `all`
# package, or a tool of any architecture (Multi-Arch: foreign). For a cross-built package only
# the name is checked: this machine holds the target's libraries, not all its tools
# (pkg-config:arm64).
if(arch STREQUAL host_arch)
  set(satisfies "(${arch}|all)/[^ ]*|[^ ]+/foreign")
else()
  set(satisfies "[^ ]+")
endif()
string(CONCAT format "-f=\${db:Status-Status} \${Architecture}/\${Multi-Arch} "
       "\${Package} \${Provides}\\n")
execute_process(COMMAND dpkg-query -W "${format}" OUTPUT_VARIABLE all_packages)
string(REGEX MATCHALL "(^|\n)installed (${satisfies}) [^\n]*" available "${all_packages}")
list(TRANSFORM available REPLACE "^\n?installed [^ ]+ " "")

# check_depends(<package> <depends> <own_names...>): every package named in a Depends line,
# alternatives too, is installed on this machine for the package's architecture or provided by
# one that is; <own_names> (hiltwin's own packages) excepted.
function(check_depends package depends)
  string(REGEX REPLACE "[,|]" ";" entries "${depends}")
  foreach(entry IN LISTS entries)
    string(STRIP "${entry}" entry)
    string(REGEX REPLACE "[ (:].*" "" name "${entry}")
    string(REGEX REPLACE "([.+])" "\\\\\\1" name_pattern "${name}")
    if(NOT name IN_LIST ARGN AND NOT available MATCHES "(^|;)([^;]*[ ,])?${name_pattern}([ ,;]|$)")
      hiltwin_test_fail("${package}'s Depends"
        WHY "'${entry}' is no Debian package installed here for ${arch}, nor provided by one\n"
            "  Depends: ${depends}"
        HINT "a wrong package name in cmake/HiltwinPackage.cmake, or bash scripts/setup.sh")
    endif()
  endforeach()
endfunction()

# hiltwin's Depends are dpkg-shlibdeps's: the Debian libraries the binary really links.
deb_field(runtime_depends "${runtime_deb}" Depends)
deb_field(runtime_version "${runtime_deb}" Version)
message(STATUS "${runtime_package} ${runtime_version} ${arch} Depends: ${runtime_depends}")
check_depends(${runtime_package} "${runtime_depends}")
foreach(library "libc6" "libstdc\\+\\+6" "libspdlog[0-9.]+(-fmt[0-9]+)?" "libfmt[0-9]+")
  if(NOT "${runtime_depends}," MATCHES "(^|, )${library}[ ,]")
    hiltwin_test_fail("${runtime_package}'s Depends"
                      WHY "no package matching '${library}' in: ${runtime_depends}"
                      HINT "CPACK_DEBIAN_PACKAGE_SHLIBDEPS must be ON "
                           "(cmake/HiltwinPackage.cmake)")
  endif()
endforeach()

deb_field(dev_depends "${dev_deb}" Depends)
message(STATUS "${dev_package} Depends: ${dev_depends}")
check_depends(${dev_package} "${dev_depends}" "${runtime_package}")
string(REPLACE "+" "\\+" version_pattern "${runtime_version}")
if(NOT "${dev_depends}," MATCHES "(^|, )${runtime_package} \\(= ${version_pattern}\\),")
  hiltwin_test_fail("${dev_package}'s Depends"
                    WHY "no '${runtime_package} (= ${runtime_version})' in: ${dev_depends}"
                    HINT "see CPACK_COMPONENT_DEV_DEPENDS in cmake/HiltwinPackage.cmake")
endif()

# An empty root: dpkg's database, nothing else. Its Depends are not there, so --force-depends;
# the programs run with this machine's libraries, which the Depends check above vouched for.
set(root "${WORK_DIR}/root")
file(MAKE_DIRECTORY "${root}/var/lib/dpkg/info" "${root}/var/lib/dpkg/updates")
file(TOUCH "${root}/var/lib/dpkg/status" "${root}/var/lib/dpkg/available")
# --log: dpkg would otherwise log into this machine's /var/log/dpkg.log.
set(dpkg_args "--root=${root}" "--log=${WORK_DIR}/dpkg.log" --force-depends)
execute_process(COMMAND id -u OUTPUT_VARIABLE uid OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT uid EQUAL 0)
  list(APPEND dpkg_args --force-not-root)
endif()
if(NOT arch STREQUAL host_arch)
  list(APPEND dpkg_args --force-architecture)  # an arm64 package checked on an amd64 machine
endif()
hiltwin_test_run("dpkg -i into ${root}" out
  COMMAND dpkg ${dpkg_args} -i "${runtime_deb}" "${dev_deb}")
hiltwin_test_run("dpkg -s in ${root}" out
  COMMAND dpkg "--root=${root}" -s "${runtime_package}" "${dev_package}")
string(REGEX MATCHALL "Status: install ok installed" installed "${out}")
list(LENGTH installed installed_count)
if(NOT installed_count EQUAL 2)
  hiltwin_test_fail("dpkg -s in ${root}" WHY "not both packages installed:\n${out}"
                    HINT "read dpkg's output above")
endif()
hiltwin_test_require_files("the installed packages"
                           "see the install rules in cmake/HiltwinInstall.cmake" "${root}"
                           usr/bin/hiltwin usr/include/hiltwin/runtime/run_session.h
                           usr/include/hiltwin/controller_abi.h
                           usr/share/bash-completion/completions/hiltwin
                           usr/share/man/man1/hiltwin.1)

hiltwin_test_check_version("${root}/usr/bin/hiltwin --version" "${root}/usr/bin/hiltwin")
hiltwin_test_run("${root}/usr/bin/hiltwin run" out EXIT_CODES 0 3
  COMMAND ${EMULATOR} "${root}/usr/bin/hiltwin" run --clock virtual --duration 1 --no-progress)
hiltwin_test_check_verdict("${root}/usr/bin/hiltwin run" "${out}" "${out_EXIT}")
