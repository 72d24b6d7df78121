# hiltwin_add_20sim_plant: one CMake line turns a folder of 20-sim generated C++ class code into
# a plant that `hiltwin run --plant NAME` finds (docs/20sim.md). The adapter is
# plant/include/hiltwin/plant/twentysim_plant.h.
#
# hiltwin_add_20sim_plant(<name>
#     CLASS <class>                       the submodel class ("LoopController")
#     INPUTS <port[:unit]>...             u[0], u[1], ... in order (may be empty)
#     OUTPUTS <port[:unit]>...            y[0], y[1], ... in order
#     [DIR <folder>]                      default: ${CMAKE_CURRENT_SOURCE_DIR}/<name>
#     [HEADER <file>]                     default: <class>.h, in DIR
#     [DESCRIPTION <text>]                one line for --help
#     [FINISH_TIME <s>]                   default 0: calculate for ever (endless HiL)
#     [EXCLUDE <file>...])                sources in DIR not to compile (a generated main.cpp)
#
# Builds the OBJECT library hiltwin_plant_<name>: every .cpp/.c of DIR, compiled as the
# generator wrote it (without hiltwin's warning set: the code is not ours), plus a generated
# registration file (cmake/twentysim_register.cpp.in) compiled with the warning set. An OBJECT
# library, because its only link-time reference is the registration's static initialiser: a
# static archive member nobody references is dropped by the linker, an object file never is.
# The target is appended to the global property HILTWIN_PLANT_LIBRARIES, which the hiltwin
# executable links.

set(_HILTWIN_20SIM_TEMPLATE "${CMAKE_CURRENT_LIST_DIR}/twentysim_register.cpp.in")

# A C++ string literal of `text`.
function(_hiltwin_20sim_literal out text)
  string(REPLACE "\\" "\\\\" text "${text}")
  string(REPLACE "\"" "\\\"" text "${text}")
  string(REPLACE "\n" " " text "${text}")
  set(${out} "\"${text}\"" PARENT_SCOPE)
endfunction()

# `specs` (name[:unit]...) as the text of a std::vector<Port> initialiser; checks every name.
function(_hiltwin_20sim_ports out plant what)
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
      message(FATAL_ERROR "hiltwin_add_20sim_plant(${plant}): ${what} '${spec}': the port name "
              "'${port}' must be letters, digits and _ (not starting with a digit), optionally "
              "followed by :unit, e.g. force_n:N")
    endif()
    if(unit MATCHES "[ \t\"\\\\]")
      message(FATAL_ERROR "hiltwin_add_20sim_plant(${plant}): ${what} '${spec}': the unit "
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
function(_hiltwin_20sim_check_counts plant class_cpp n_inputs n_outputs)
  if(NOT EXISTS "${class_cpp}")
    message(STATUS "hiltwin_add_20sim_plant(${plant}): no ${class_cpp}: port counts not checked")
    return()
  endif()
  file(STRINGS "${class_cpp}" out_lines REGEX "^[ \t]*y\\[[0-9]+\\][ \t]*=")
  if(NOT out_lines)
    message(STATUS "hiltwin_add_20sim_plant(${plant}): no 'y[N] = ...' lines in ${class_cpp}: "
            "port counts not checked")
    return()
  endif()
  file(STRINGS "${class_cpp}" in_lines REGEX "=[ \t]*u\\[[0-9]+\\][ \t]*;")
  _hiltwin_20sim_count(code_outputs "y" "${out_lines}")
  _hiltwin_20sim_count(code_inputs "u" "${in_lines}")
  if(NOT code_outputs EQUAL n_outputs OR NOT code_inputs EQUAL n_inputs)
    list(JOIN in_lines "\n" in_text)
    list(JOIN out_lines "\n" out_text)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${plant}): ${class_cpp} reads ${code_inputs} "
            "inputs u[] and writes ${code_outputs} outputs y[], but INPUTS names ${n_inputs} and "
            "OUTPUTS names ${n_outputs}. Name one port per u[i]/y[i], in index order; the "
            "generated lines (20-sim's names in the comments):\n${in_text}\n${out_text}")
  endif()
endfunction()

# Two 20-sim plants in one executable would define the same symbols twice (every generated
# folder has its own xxinteg.cpp, xxmatrix.cpp... and the thesis names every submodel
# LoopController): refuse here rather than at the executable's link.
function(_hiltwin_20sim_check_clash plant class sources)
  get_property(seen GLOBAL PROPERTY _HILTWIN_20SIM_SEEN)  # "plant|class|file;..."
  foreach(entry IN LISTS seen)
    string(REPLACE "|" ";" parts "${entry}")
    list(GET parts 0 other)
    list(GET parts 1 other_class)
    list(GET parts 2 other_file)
    set(clash "")
    if(other_class STREQUAL class)
      set(clash "both are the class ${class}")
    else()
      foreach(source IN LISTS sources)
        get_filename_component(file "${source}" NAME)
        if(file STREQUAL other_file)
          set(clash "both compile ${file}")
        endif()
      endforeach()
    endif()
    if(clash)
      message(FATAL_ERROR "hiltwin_add_20sim_plant(${plant}): the 20-sim plant '${other}' is "
              "already in this build and ${clash}: their symbols would be defined twice in the "
              "hiltwin executable. One 20-sim plant per build for now (docs/20sim.md, Limits): "
              "use a second build directory, or give the submodels different names in 20-sim "
              "and share one copy of the xx* support files.")
    endif()
  endforeach()
  foreach(source IN LISTS sources)
    get_filename_component(file "${source}" NAME)
    set_property(GLOBAL APPEND PROPERTY _HILTWIN_20SIM_SEEN "${plant}|${class}|${file}")
  endforeach()
endfunction()

# The generated sources of `dir`, without EXCLUDE and without a file defining main (20-sim may
# put an example main.cpp next to the class; the hiltwin executable has its own).
function(_hiltwin_20sim_sources out plant dir)
  file(GLOB sources CONFIGURE_DEPENDS "${dir}/*.cpp" "${dir}/*.c")
  set(kept)
  foreach(source IN LISTS sources)
    get_filename_component(file "${source}" NAME)
    if(file IN_LIST ARGN)
      continue()
    endif()
    file(STRINGS "${source}" mains REGEX "^[ \t]*(int|void)[ \t]+main[ \t]*\\(")
    if(mains)
      message(STATUS "hiltwin_add_20sim_plant(${plant}): ${file} defines main(): not compiled")
      continue()
    endif()
    list(APPEND kept "${source}")
  endforeach()
  if(NOT kept)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${plant}): no .cpp or .c files in ${dir}: "
            "copy the whole folder 20-sim generated there")
  endif()
  set(${out} "${kept}" PARENT_SCOPE)
endfunction()

# Checks the arguments; sets ARG_DIR, ARG_HEADER (absolute), ARG_FINISH_TIME in the caller.
macro(_hiltwin_20sim_check_args name)
  if(NOT "${name}" MATCHES "^[A-Za-z][A-Za-z0-9_]*$")
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): the plant name must be letters, "
            "digits and _ starting with a letter (it is --plant NAME and part of a target name)")
  endif()
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): unexpected arguments "
            "'${ARG_UNPARSED_ARGUMENTS}': the keywords are CLASS, INPUTS, OUTPUTS, DIR, HEADER, "
            "DESCRIPTION, FINISH_TIME, EXCLUDE")
  endif()
  if(NOT ARG_CLASS)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): CLASS <class> is missing: the name of "
            "the submodel class 20-sim generated (thesis: LoopController)")
  endif()
  if(NOT ARG_CLASS MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): CLASS '${ARG_CLASS}' is not a C++ "
            "class name")
  endif()
  if(NOT ARG_OUTPUTS)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): OUTPUTS <port[:unit]>... is missing: "
            "name the submodel's outputs y[0], y[1], ... in order")
  endif()
  if(NOT ARG_DIR)
    set(ARG_DIR "${CMAKE_CURRENT_SOURCE_DIR}/${name}")
  endif()
  get_filename_component(ARG_DIR "${ARG_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT IS_DIRECTORY "${ARG_DIR}")
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): the folder ${ARG_DIR} does not exist: "
            "copy 20-sim's output folder there, or give DIR <folder>")
  endif()
  if(NOT ARG_HEADER)
    set(ARG_HEADER "${ARG_CLASS}.h")
  endif()
  get_filename_component(ARG_HEADER "${ARG_HEADER}" ABSOLUTE BASE_DIR "${ARG_DIR}")
  if(NOT EXISTS "${ARG_HEADER}")
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): the header ${ARG_HEADER} does not "
            "exist: 20-sim names it after the submodel (CLASS ${ARG_CLASS}); give HEADER <file> "
            "if yours differs")
  endif()
  file(STRINGS "${ARG_HEADER}" class_lines REGEX "class[ \t]+${ARG_CLASS}([^A-Za-z0-9_]|$)")
  if(NOT class_lines)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): ${ARG_HEADER} does not declare class "
            "${ARG_CLASS}: CLASS must be the submodel's name as 20-sim wrote it")
  endif()
  if("${ARG_FINISH_TIME}" STREQUAL "")
    set(ARG_FINISH_TIME 0)
  endif()
  if(NOT ARG_FINISH_TIME MATCHES "^[0-9]+(\\.[0-9]*)?([eE][-+]?[0-9]+)?$")
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): FINISH_TIME '${ARG_FINISH_TIME}' must "
            "be a time in seconds >= 0 (0: for ever)")
  endif()
  _hiltwin_20sim_port_names(all_ports ${ARG_INPUTS} ${ARG_OUTPUTS})
  set(unique_ports ${all_ports})
  list(REMOVE_DUPLICATES unique_ports)
  if(NOT all_ports STREQUAL unique_ports)
    message(FATAL_ERROR "hiltwin_add_20sim_plant(${name}): a port name is used twice in "
            "'${all_ports}': every input and output needs its own name")
  endif()
endmacro()

function(hiltwin_add_20sim_plant name)
  cmake_parse_arguments(ARG "" "CLASS;DIR;HEADER;DESCRIPTION;FINISH_TIME"
                        "INPUTS;OUTPUTS;EXCLUDE" ${ARGN})
  _hiltwin_20sim_check_args(${name})
  _hiltwin_20sim_sources(sources ${name} "${ARG_DIR}" ${ARG_EXCLUDE})
  list(LENGTH ARG_INPUTS n_inputs)
  list(LENGTH ARG_OUTPUTS n_outputs)
  _hiltwin_20sim_check_counts(${name} "${ARG_DIR}/${ARG_CLASS}.cpp" ${n_inputs} ${n_outputs})
  _hiltwin_20sim_check_clash(${name} ${ARG_CLASS} "${sources}")

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
  set(HILTWIN_20SIM_PLANT "${name}")
  set(HILTWIN_20SIM_CLASS "${ARG_CLASS}")
  set(HILTWIN_20SIM_HEADER "${ARG_HEADER}")
  set(HILTWIN_20SIM_FINISH_TIME "${ARG_FINISH_TIME}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_NAME_LITERAL "${name}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_CLASS_LITERAL "${ARG_CLASS}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_DESCRIPTION_LITERAL "${ARG_DESCRIPTION}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_INTEGRATOR_LITERAL "${integrator}")
  _hiltwin_20sim_literal(HILTWIN_20SIM_DIR_LITERAL "${ARG_DIR}")
  _hiltwin_20sim_ports(HILTWIN_20SIM_INPUTS ${name} INPUTS ${ARG_INPUTS})
  _hiltwin_20sim_ports(HILTWIN_20SIM_OUTPUTS ${name} OUTPUTS ${ARG_OUTPUTS})
  set(register "${CMAKE_CURRENT_BINARY_DIR}/hiltwin_20sim_${name}_register.cpp")
  configure_file("${_HILTWIN_20SIM_TEMPLATE}" "${register}" @ONLY)

  set(target hiltwin_plant_${name})
  add_library(${target} OBJECT ${sources} "${register}")
  # PUBLIC: tests (and tools) may build the adapter over the class themselves.
  target_include_directories(${target} PUBLIC "${ARG_DIR}")
  target_link_libraries(${target} PUBLIC hiltwin::plant)
  # hiltwin's warning set for the registration file only: take what hiltwin_target_warnings
  # gives the target and move it onto that one source, so the set stays defined in one place.
  hiltwin_target_warnings(${target})
  get_target_property(warning_options ${target} COMPILE_OPTIONS)
  set_property(TARGET ${target} PROPERTY COMPILE_OPTIONS "")
  set_source_files_properties("${register}" PROPERTIES COMPILE_OPTIONS "${warning_options}")
  set_property(GLOBAL APPEND PROPERTY HILTWIN_PLANT_LIBRARIES ${target})
  message(STATUS "hiltwin: 20-sim plant '${name}' (${ARG_CLASS}, ${integrator}) from ${ARG_DIR}")
endfunction()
