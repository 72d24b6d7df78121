# hiltwin_add_20sim_plant / hiltwin_add_20sim_controller: one CMake line turns a folder of
# 20-sim generated C++ class code into a plant that `hiltwin run --plant NAME` finds, or a
# controller that `hiltwin ecs --controller 20sim:NAME` finds (docs/20sim.md). The adapters are
# plant/include/hiltwin/plant/twentysim_plant.h and
# controller/include/hiltwin/controller/twentysim_controller.h, over the life cycle both share
# (plant/include/hiltwin/plant/twentysim_submodel.h).
#
# hiltwin_add_20sim_plant(<name>            (and hiltwin_add_20sim_controller, the same keywords)
#     CLASS <class>                       the submodel class ("LoopController")
#     INPUTS <port[:unit]>...             u[0], u[1], ... in order (may be empty)
#     OUTPUTS <port[:unit]>...            y[0], y[1], ... in order
#     [DIR <folder>]                      default: ${CMAKE_CURRENT_SOURCE_DIR}/<name>
#     [HEADER <file>]                     default: <class>.h, in DIR
#     [DESCRIPTION <text>]                one line for --help
#     [FINISH_TIME <s>]                   default 0: calculate for ever (endless HiL)
#     [EXCLUDE <file>...])                sources in DIR not to compile (a generated main.cpp)
#
# Builds the OBJECT library hiltwin_plant_<name> / hiltwin_controller_<name>: the class's own
# .cpp, compiled as the generator wrote it (without hiltwin's warning set: the code is not ours)
# with the class renamed for this build, plus a generated registration file
# (cmake/twentysim_register.cpp.in, cmake/twentysim_register_controller.cpp.in) compiled with
# the warning set. The folder's other sources (xxinteg.cpp, ...) go into support OBJECT
# libraries shared by every folder with the same bytes (_hiltwin_20sim_share_support). OBJECT
# libraries, because their only link-time reference is the registration's static initialiser:
# a static archive member nobody references is dropped by the linker, an object file never is.
# The targets are appended to the global property HILTWIN_PLANT_LIBRARIES or
# HILTWIN_CONTROLLER_LIBRARIES (a support library to the one of the first folder using it),
# which the hiltwin executable links; a test links one 20-sim target with hiltwin_link_20sim.

set(_HILTWIN_20SIM_TEMPLATE_plant "${CMAKE_CURRENT_LIST_DIR}/twentysim_register.cpp.in")
set(_HILTWIN_20SIM_TEMPLATE_controller
    "${CMAKE_CURRENT_LIST_DIR}/twentysim_register_controller.cpp.in")

# A C++ string literal of `text`.
function(_hiltwin_20sim_literal out text)
  string(REPLACE "\\" "\\\\" text "${text}")
  string(REPLACE "\"" "\\\"" text "${text}")
  string(REPLACE "\n" " " text "${text}")
  set(${out} "\"${text}\"" PARENT_SCOPE)
endfunction()

# `specs` (name[:unit]...) as the text of a std::vector<Port> initialiser; checks every name.
function(_hiltwin_20sim_ports out who what)
  set(items)
  foreach(spec IN LISTS ARGN)
    string(FIND "${spec}" ":" colon)
    if(colon EQUAL -1)
      set(port "${spec}")
      set(unit "")
    else()
      string(SUBSTRING "${spec}" 0 ${colon} port)
      math(EXPR after "${colon} + 1")
      string(SUBSTRING "${spec}" ${after} -1 unit)
    endif()
    if(NOT port MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
      message(FATAL_ERROR "${who}: ${what} '${spec}': the port name "
              "'${port}' must be letters, digits and _ (not starting with a digit), optionally "
              "followed by :unit, e.g. force_n:N")
    endif()
    if(unit MATCHES "[ \t\"\\\\]")
      message(FATAL_ERROR "${who}: ${what} '${spec}': the unit "
              "'${unit}' may not contain spaces, quotes or backslashes (m, rad, N, m/s, 1)")
    endif()
    _hiltwin_20sim_literal(name_text "${port}")
    _hiltwin_20sim_literal(unit_text "${unit}")
    list(APPEND items "{${name_text}, ${unit_text}}")
  endforeach()
  list(JOIN items ", " joined)
  set(${out} "${joined}" PARENT_SCOPE)
endfunction()

# The port names without units, for the duplicate check.
function(_hiltwin_20sim_port_names out)
  set(names)
  foreach(spec IN LISTS ARGN)
    string(REGEX REPLACE ":.*$" "" port "${spec}")
    list(APPEND names "${port}")
  endforeach()
  set(${out} "${names}" PARENT_SCOPE)
endfunction()

# Number of distinct indices `array`[N] in `lines`.
function(_hiltwin_20sim_count out array lines)
  set(indices)
  foreach(line IN LISTS lines)
    string(REGEX MATCHALL "${array}\\[[0-9]+\\]" hits "${line}")
    foreach(hit IN LISTS hits)
      string(REGEX REPLACE "^.*\\[([0-9]+)\\]$" "\\1" index "${hit}")
      list(APPEND indices ${index})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES indices)
  list(LENGTH indices count)
  set(${out} ${count} PARENT_SCOPE)
endfunction()

# 20-sim writes `m_V[0] = u[0];  /* name */` in CopyInputsToVariables and `y[0] = m_V[1];
# /* name */` in CopyVariablesToOutputs. The generated code carries no port count the compiler
# could check, and a CMake line with fewer ports than the code writes would let Calculate write
# past the adapter's buffers: so count them here when the class file has that shape.
function(_hiltwin_20sim_check_counts who class_cpp n_inputs n_outputs)
  if(NOT EXISTS "${class_cpp}")
    message(STATUS "${who}: no ${class_cpp}: port counts not checked")
    return()
  endif()
  file(STRINGS "${class_cpp}" out_lines REGEX "^[ \t]*y\\[[0-9]+\\][ \t]*=")
  if(NOT out_lines)
    message(STATUS "${who}: no 'y[N] = ...' lines in ${class_cpp}: "
            "port counts not checked")
    return()
  endif()
  file(STRINGS "${class_cpp}" in_lines REGEX "=[ \t]*u\\[[0-9]+\\][ \t]*;")
  _hiltwin_20sim_count(code_outputs "y" "${out_lines}")
  _hiltwin_20sim_count(code_inputs "u" "${in_lines}")
  if(NOT code_outputs EQUAL n_outputs OR NOT code_inputs EQUAL n_inputs)
    list(JOIN in_lines "\n" in_text)
    list(JOIN out_lines "\n" out_text)
    message(FATAL_ERROR "${who}: ${class_cpp} reads ${code_inputs} "
            "inputs u[] and writes ${code_outputs} outputs y[], but INPUTS names ${n_inputs} and "
            "OUTPUTS names ${n_outputs}. Name one port per u[i]/y[i], in index order; the "
            "generated lines (20-sim's names in the comments):\n${in_text}\n${out_text}")
  endif()
endfunction()

# Every 20-sim folder carries the same support files (xxinteg.cpp, xxmatrix.cpp, ...,
# Submodel20sim.h) and the thesis names every submodel LoopController, so a 20-sim plant and a
# 20-sim controller in one executable would define the same symbols twice. Two measures keep
# them apart: the class is renamed per folder (a compile definition CLASS=hiltwin_20sim_<name>_
# CLASS on its target, so two LoopControllers are two classes), and a support source is
# compiled once, into an OBJECT library of its own shared by every folder holding the same
# bytes. Same-named support files (sources or headers) that differ cannot share one definition:
# refused here rather than at the executable's link. Sets `out` to the support libraries.
function(_hiltwin_20sim_share_support out who role class dir sources)
  file(GLOB headers "${dir}/*.h" "${dir}/*.hpp")
  set(libraries)
  foreach(file_path IN LISTS sources headers)
    get_filename_component(file "${file_path}" NAME)
    get_filename_component(stem "${file_path}" NAME_WE)
    if(stem STREQUAL class)  # the class's own .cpp and .h: renamed, never shared
      continue()
    endif()
    file(SHA256 "${file_path}" hash)
    get_property(known GLOBAL PROPERTY "_HILTWIN_20SIM_FILE_${file}")  # "hash|who|lib"
    if(known)
      string(REPLACE "|" ";" parts "${known}")
      list(GET parts 0 known_hash)
      list(GET parts 1 known_who)
      list(GET parts 2 known_library)
      if(NOT known_hash STREQUAL hash)
        message(FATAL_ERROR "${who}: ${dir}/${file} differs from the ${file} of ${known_who}: "
                "the two would define the same symbols differently in the hiltwin executable. "
                "Generate both with the same 20-sim version, or build them in two build "
                "directories (docs/20sim.md, Limits).")
      endif()
    else()
      set(known_library none)
      if(file_path IN_LIST sources)
        string(SUBSTRING "${hash}" 0 12 short)
        string(MAKE_C_IDENTIFIER "hiltwin_20sim_support_${stem}_${short}" known_library)
        add_library(${known_library} OBJECT "${file_path}")
        target_include_directories(${known_library} PRIVATE "${dir}")
        # In the list of the first folder's role, so a consumer of both lists (the hiltwin
        # executable) links it once, and one of the plants' alone (tests, fuzzers) has it.
        string(TOUPPER "${role}" role_upper)
        set_property(GLOBAL APPEND PROPERTY HILTWIN_${role_upper}_LIBRARIES ${known_library})
      endif()
      set_property(GLOBAL PROPERTY "_HILTWIN_20SIM_FILE_${file}" "${hash}|${who}|${known_library}")
    endif()
    if(NOT known_library STREQUAL "none")
      list(APPEND libraries ${known_library})
    endif()
  endforeach()
  set(${out} "${libraries}" PARENT_SCOPE)
endfunction()

# The SHA-256 of a generated folder, for a controller's run report: over the sorted names and
# bytes' SHA-256 of its .cpp, .c and .h files. Editing one of them re-runs CMake (so the hash
# never describes older code than the one compiled).
function(_hiltwin_20sim_folder_hash out dir)
  file(GLOB files "${dir}/*.cpp" "${dir}/*.c" "${dir}/*.h" "${dir}/*.hpp")
  list(SORT files)
  set(listing "")
  foreach(file_path IN LISTS files)
    get_filename_component(file "${file_path}" NAME)
    file(SHA256 "${file_path}" hash)
    string(APPEND listing "${hash}  ${file}\n")
  endforeach()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${files})
  string(SHA256 folder_hash "${listing}")
  set(${out} "${folder_hash}" PARENT_SCOPE)
endfunction()

# hiltwin_link_20sim(<consumer> <20-sim target>): links the OBJECT library of a 20-sim plant or
# controller and the support libraries it shares, and gives the consumer the class's name in
# this build (a test that builds the adapter over the class itself; one 20-sim target each).
function(hiltwin_link_20sim consumer target)
  get_target_property(support ${target} HILTWIN_20SIM_SUPPORT)
  get_target_property(rename ${target} HILTWIN_20SIM_RENAME)
  target_link_libraries(${consumer} PRIVATE ${target} ${support})
  target_compile_definitions(${consumer} PRIVATE "${rename}")
endfunction()

# The generated sources of `dir`, without EXCLUDE and without a file defining main (20-sim may
# put an example main.cpp next to the class; the hiltwin executable has its own).
function(_hiltwin_20sim_sources out who dir)
  file(GLOB sources CONFIGURE_DEPENDS "${dir}/*.cpp" "${dir}/*.c")
  set(kept)
  foreach(source IN LISTS sources)
    get_filename_component(file "${source}" NAME)
    if(file IN_LIST ARGN)
      continue()
    endif()
    file(STRINGS "${source}" mains REGEX "^[ \t]*(int|void)[ \t]+main[ \t]*\\(")
    if(mains)
      message(STATUS "${who}: ${file} defines main(): not compiled")
      continue()
    endif()
    list(APPEND kept "${source}")
  endforeach()
  if(NOT kept)
    message(FATAL_ERROR "${who}: no .cpp or .c files in ${dir}: "
            "copy the whole folder 20-sim generated there")
  endif()
  set(${out} "${kept}" PARENT_SCOPE)
endfunction()

# Checks the arguments; sets ARG_DIR, ARG_HEADER (absolute), ARG_FINISH_TIME in the caller.
macro(_hiltwin_20sim_check_args who name)
  if(NOT "${name}" MATCHES "^[A-Za-z][A-Za-z0-9_]*$")
    message(FATAL_ERROR "${who}: the name must be letters, digits and _ starting with a "
            "letter (it is --plant NAME or --controller 20sim:NAME, and part of a target name)")
  endif()
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "${who}: unexpected arguments "
            "'${ARG_UNPARSED_ARGUMENTS}': the keywords are CLASS, INPUTS, OUTPUTS, DIR, HEADER, "
            "DESCRIPTION, FINISH_TIME, EXCLUDE")
  endif()
  if(NOT ARG_CLASS)
    message(FATAL_ERROR "${who}: CLASS <class> is missing: the name of "
            "the submodel class 20-sim generated (thesis: LoopController)")
  endif()
  if(NOT ARG_CLASS MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "${who}: CLASS '${ARG_CLASS}' is not a C++ "
            "class name")
  endif()
  if(NOT ARG_OUTPUTS)
    message(FATAL_ERROR "${who}: OUTPUTS <port[:unit]>... is missing: "
            "name the submodel's outputs y[0], y[1], ... in order")
  endif()
  if(NOT ARG_DIR)
    set(ARG_DIR "${CMAKE_CURRENT_SOURCE_DIR}/${name}")
  endif()
  get_filename_component(ARG_DIR "${ARG_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT IS_DIRECTORY "${ARG_DIR}")
    message(FATAL_ERROR "${who}: the folder ${ARG_DIR} does not exist: "
            "copy 20-sim's output folder there, or give DIR <folder>")
  endif()
  if(NOT ARG_HEADER)
    set(ARG_HEADER "${ARG_CLASS}.h")
  endif()
  get_filename_component(ARG_HEADER "${ARG_HEADER}" ABSOLUTE BASE_DIR "${ARG_DIR}")
  if(NOT EXISTS "${ARG_HEADER}")
    message(FATAL_ERROR "${who}: the header ${ARG_HEADER} does not "
            "exist: 20-sim names it after the submodel (CLASS ${ARG_CLASS}); give HEADER <file> "
            "if yours differs")
  endif()
  file(STRINGS "${ARG_HEADER}" class_lines REGEX "class[ \t]+${ARG_CLASS}([^A-Za-z0-9_]|$)")
  if(NOT class_lines)
    message(FATAL_ERROR "${who}: ${ARG_HEADER} does not declare class "
            "${ARG_CLASS}: CLASS must be the submodel's name as 20-sim wrote it")
  endif()
  if("${ARG_FINISH_TIME}" STREQUAL "")
    set(ARG_FINISH_TIME 0)
  endif()
  if(NOT ARG_FINISH_TIME MATCHES "^[0-9]+(\\.[0-9]*)?([eE][-+]?[0-9]+)?$")
    message(FATAL_ERROR "${who}: FINISH_TIME '${ARG_FINISH_TIME}' must "
            "be a time in seconds >= 0 (0: for ever)")
  endif()
  _hiltwin_20sim_port_names(all_ports ${ARG_INPUTS} ${ARG_OUTPUTS})
  set(unique_ports ${all_ports})
  list(REMOVE_DUPLICATES unique_ports)
  if(NOT all_ports STREQUAL unique_ports)
    message(FATAL_ERROR "${who}: a port name is used twice in "
            "'${all_ports}': every input and output needs its own name")
  endif()
endmacro()


# What hiltwin_add_20sim_plant and hiltwin_add_20sim_controller share: `role` is plant or
# controller; builds the OBJECT library hiltwin_<role>_<name> and appends it to the global
# property HILTWIN_<ROLE>_LIBRARIES.
function(_hiltwin_add_20sim role name)
  set(who "hiltwin_add_20sim_${role}(${name})")
  cmake_parse_arguments(ARG "" "CLASS;DIR;HEADER;DESCRIPTION;FINISH_TIME"
                        "INPUTS;OUTPUTS;EXCLUDE" ${ARGN})
  _hiltwin_20sim_check_args("${who}" ${name})
  _hiltwin_20sim_sources(sources "${who}" "${ARG_DIR}" ${ARG_EXCLUDE})
  list(LENGTH ARG_INPUTS n_inputs)
  list(LENGTH ARG_OUTPUTS n_outputs)
  _hiltwin_20sim_check_counts("${who}" "${ARG_DIR}/${ARG_CLASS}.cpp" ${n_inputs} ${n_outputs})
  _hiltwin_20sim_share_support(support "${who}" ${role} ${ARG_CLASS} "${ARG_DIR}" "${sources}")

  # The integrator is a private member; the header is the only place that names it.
  file(STRINGS "${ARG_HEADER}" integ_lines REGEX "[A-Za-z0-9_]+[ \t]+myintegmethod[ \t]*;")
  set(integrator "")
  if(integ_lines)
    list(GET integ_lines 0 integ_line)
    string(REGEX REPLACE "^(.*[^A-Za-z0-9_])?([A-Za-z_][A-Za-z0-9_]*)[ \t]+myintegmethod.*$"
           "\\2" integrator "${integ_line}")
    string(STRIP "${integrator}" integrator)
  endif()
  if(NOT ARG_DESCRIPTION)
    set(ARG_DESCRIPTION "20-sim submodel ${ARG_CLASS} (${ARG_DIR})")
  endif()

  # The values configure_file puts into the template.
  set(HILTWIN_20SIM_NAME "${name}")
  set(HILTWIN_20SIM_CLASS "${ARG_CLASS}")
  set(HILTWIN_20SIM_HEADER "${ARG_HEADER}")
  set(HILTWIN_20SIM_FINISH_TIME "${ARG_FINISH_TIME}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_NAME_LITERAL "${name}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_CLASS_LITERAL "${ARG_CLASS}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_DESCRIPTION_LITERAL "${ARG_DESCRIPTION}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_INTEGRATOR_LITERAL "${integrator}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_DIR_LITERAL "${ARG_DIR}")
  _hiltwin_20sim_folder_hash(HILTWIN_20SIM_CONTENT_SHA256 "${ARG_DIR}")
  _hiltwin_20sim_ports(HILTWIN_20SIM_INPUTS "${who}" INPUTS ${ARG_INPUTS})
  _hiltwin_20sim_ports(HILTWIN_20SIM_OUTPUTS "${who}" OUTPUTS ${ARG_OUTPUTS})
  set(register "${CMAKE_CURRENT_BINARY_DIR}/hiltwin_20sim_${name}_register.cpp")
  configure_file("${_HILTWIN_20SIM_TEMPLATE_${role}}" "${register}" @ONLY)

  # The class's own sources; the others are in the support libraries.
  set(class_sources)
  foreach(source IN LISTS sources)
    get_filename_component(stem "${source}" NAME_WE)
    if(stem STREQUAL ARG_CLASS)
      list(APPEND class_sources "${source}")
    endif()
  endforeach()
  set(target hiltwin_${role}_${name})
  add_library(${target} OBJECT ${class_sources} "${register}")
  # PUBLIC: tests (and tools) may build the adapter over the class themselves. The class's name
  # in this build (_hiltwin_20sim_share_support says why it is renamed) is private: the hiltwin
  # executable links several 20-sim targets; hiltwin_link_20sim gives it to a test.
  set(rename "${ARG_CLASS}=hiltwin_20sim_${name}_${ARG_CLASS}")
  target_include_directories(${target} PUBLIC "${ARG_DIR}")
  target_compile_definitions(${target} PRIVATE "${rename}")
  target_link_libraries(${target} PUBLIC hiltwin::${role})
  set_property(TARGET ${target} PROPERTY HILTWIN_20SIM_SUPPORT "${support}")
  set_property(TARGET ${target} PROPERTY HILTWIN_20SIM_RENAME "${rename}")
  # hiltwin's warning set for the registration file only: take what hiltwin_target_warnings
  # gives the target and move it onto that one source, so the set stays defined in one place.
  hiltwin_target_warnings(${target})
  get_target_property(warning_options ${target} COMPILE_OPTIONS)
  set_property(TARGET ${target} PROPERTY COMPILE_OPTIONS "")
  set_source_files_properties("${register}" PROPERTIES COMPILE_OPTIONS "${warning_options}")
  string(TOUPPER "${role}" role_upper)
  set_property(GLOBAL APPEND PROPERTY HILTWIN_${role_upper}_LIBRARIES ${target})
  message(STATUS "hiltwin: 20-sim ${role} '${name}' (${ARG_CLASS}, ${integrator}) from ${ARG_DIR}")
endfunction()

function(hiltwin_add_20sim_plant name)
  _hiltwin_add_20sim(plant ${name} ${ARGN})
endfunction()

function(hiltwin_add_20sim_controller name)
  _hiltwin_add_20sim(controller ${name} ${ARGN})
endfunction()
