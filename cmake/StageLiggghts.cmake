# Stage the upstream LIGGGHTS-PUBLIC 3.8.0 tree into the build directory, apply our patches,
# and generate the style headers (what upstream's Make.sh does, done here in CMake so that
# the build needs nothing but CMake and a compiler).
#
# Inputs : LIGGGHTS_SOURCE_DIR (upstream tree, contains src/lammps.cpp)
#          TSG_OVERLAY_DIR     (src-liggghts-eepa: our styles in feature folders, patches/,
#                               contact/contact_models.list)
# Outputs: TSG_STAGED_SRC      (patched upstream sources; generated style_*.h live there)
#          TSG_UPSTREAM_SOURCES (list of upstream .cpp files to compile)
#          TSG_OVERLAY_SOURCES, TSG_OVERLAY_HEADERS (our .cpp / .h files, in any folder below the overlay)
#          TSG_OVERLAY_INCLUDE_DIRS (every overlay folder that holds one of them)
#
# Files are written only when their content changes, so re-configuring keeps timestamps and a
# rebuild after touching one extension file recompiles only what depends on it.

function(tsg_write_if_different path content)
  if(EXISTS "${path}")
    file(READ "${path}" old)
    if(old STREQUAL content)
      return()
    endif()
  endif()
  file(WRITE "${path}" "${content}")
endfunction()

# ---- 0. our overlay ----------------------------------------------------------------------------
# Every .h and .cpp below src-liggghts-eepa/, in whatever folder (contact/, measure/, a new one, or
# the top level). LIGGGHTS includes a style's header by its bare name (the generated style_*.h), so
# the overlay stays one flat namespace, as if copied into upstream's src/: each of its folders is an
# include directory, and no two files may share a name.
file(GLOB_RECURSE TSG_OVERLAY_HEADERS CONFIGURE_DEPENDS "${TSG_OVERLAY_DIR}/*.h")
file(GLOB_RECURSE TSG_OVERLAY_SOURCES CONFIGURE_DEPENDS "${TSG_OVERLAY_DIR}/*.cpp")
list(SORT TSG_OVERLAY_HEADERS)
list(SORT TSG_OVERLAY_SOURCES)
set(TSG_OVERLAY_INCLUDE_DIRS "")
set(overlay_names "")
foreach(f IN LISTS TSG_OVERLAY_HEADERS TSG_OVERLAY_SOURCES)
  get_filename_component(dir "${f}" DIRECTORY)
  get_filename_component(name "${f}" NAME)
  if(name IN_LIST overlay_names)
    message(FATAL_ERROR "two files below ${TSG_OVERLAY_DIR} are named '${name}' (one is ${f}): the overlay is "
                        "one flat namespace (LIGGGHTS includes headers by bare name); rename one")
  endif()
  list(APPEND overlay_names "${name}")
  list(APPEND TSG_OVERLAY_INCLUDE_DIRS "${dir}")
endforeach()
list(REMOVE_DUPLICATES TSG_OVERLAY_INCLUDE_DIRS)

# ---- 1. validate the upstream tree ------------------------------------------------------------
if(NOT EXISTS "${LIGGGHTS_SOURCE_DIR}/src/lammps.cpp"
   OR NOT EXISTS "${LIGGGHTS_SOURCE_DIR}/src/version_liggghts.txt")
  message(FATAL_ERROR
    "LIGGGHTS_SOURCE_DIR='${LIGGGHTS_SOURCE_DIR}' is not a LIGGGHTS-PUBLIC tree "
    "(expected src/lammps.cpp and src/version_liggghts.txt). Pass the directory that contains "
    "src/, or run ./tsg setup to fetch LIGGGHTS-PUBLIC 3.8.0.")
endif()
file(STRINGS "${LIGGGHTS_SOURCE_DIR}/src/version_liggghts.txt" upstream_version LIMIT_COUNT 1)
if(NOT upstream_version STREQUAL "3.8.0")
  message(FATAL_ERROR
    "LIGGGHTS_SOURCE_DIR='${LIGGGHTS_SOURCE_DIR}' holds LIGGGHTS version '${upstream_version}'; "
    "this project is built and tested against 3.8.0 only.")
endif()

set(TSG_STAGED_SRC "${CMAKE_BINARY_DIR}/liggghts/src")
set(scratch "${CMAKE_BINARY_DIR}/liggghts/scratch")

# ---- 2. copy + patch into a scratch tree, then sync changed files into the staged tree ----------
file(GLOB upstream_files LIST_DIRECTORIES false
     "${LIGGGHTS_SOURCE_DIR}/src/*.cpp" "${LIGGGHTS_SOURCE_DIR}/src/*.h")
file(GLOB patch_files "${TSG_OVERLAY_DIR}/patches/*.patch")
list(SORT patch_files)

# Re-stage only when the upstream tree or a patch changed.
set(stage_key "${LIGGGHTS_SOURCE_DIR}")
foreach(p IN LISTS patch_files)
  file(SHA256 "${p}" h)
  string(APPEND stage_key ";${p}=${h}")
endforeach()
set(stage_stamp "${CMAKE_BINARY_DIR}/liggghts/stage.stamp")
set(old_key "")
if(EXISTS "${stage_stamp}")
  file(READ "${stage_stamp}" old_key)
endif()

if(NOT old_key STREQUAL stage_key)
  find_program(PATCH_EXECUTABLE patch)
  if(NOT PATCH_EXECUTABLE)
    message(FATAL_ERROR "the 'patch' program is needed to apply src-liggghts-eepa/patches (apt-get install patch)")
  endif()
  list(LENGTH patch_files npatches)
  message(STATUS "Staging LIGGGHTS from ${LIGGGHTS_SOURCE_DIR}, applying ${npatches} patches")
  file(REMOVE_RECURSE "${scratch}")
  file(MAKE_DIRECTORY "${scratch}/src")
  file(COPY ${upstream_files} DESTINATION "${scratch}/src")
  foreach(p IN LISTS patch_files)
    execute_process(COMMAND "${PATCH_EXECUTABLE}" -p1 --batch --forward --no-backup-if-mismatch -i "${p}"
                    WORKING_DIRECTORY "${scratch}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "patch ${p} does not apply to ${LIGGGHTS_SOURCE_DIR}:\n${out}")
    endif()
  endforeach()
  file(MAKE_DIRECTORY "${TSG_STAGED_SRC}")
  file(GLOB scratch_files LIST_DIRECTORIES false "${scratch}/src/*")
  foreach(f IN LISTS scratch_files)
    get_filename_component(name "${f}" NAME)
    execute_process(COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${f}" "${TSG_STAGED_SRC}/${name}")
  endforeach()
  file(REMOVE_RECURSE "${scratch}")
  file(WRITE "${stage_stamp}" "${stage_key}")
endif()

file(GLOB TSG_UPSTREAM_SOURCES "${TSG_STAGED_SRC}/*.cpp")

# ---- 3. style headers ----------------------------------------------------------------------------
# Upstream's Make.sh: style_<name>.h includes every <prefix>*.h that mentions <macro>.
# Our overlay headers take part exactly like upstream ones; none may take an upstream header's name
# (it would hide that header from every file that includes it).
file(GLOB staged_headers "${TSG_STAGED_SRC}/*.h")
foreach(h IN LISTS TSG_OVERLAY_HEADERS)
  get_filename_component(name "${h}" NAME)
  if(EXISTS "${TSG_STAGED_SRC}/${name}" AND NOT name MATCHES "^style_")
    message(FATAL_ERROR "${h} has the name of an upstream LIGGGHTS header; change upstream with a patch "
                        "(src-liggghts-eepa/patches) or rename the file")
  endif()
endforeach()
set(style_table
  "ANGLE_CLASS|angle_|angle" "ATOM_CLASS|atom_vec_|atom" "BODY_CLASS|body_|body"
  "BOND_CLASS|bond_|bond" "COMMAND_CLASS||command" "COMPUTE_CLASS|compute_|compute"
  "DIHEDRAL_CLASS|dihedral_|dihedral" "DUMP_CLASS|dump_|dump" "FIX_CLASS|fix_|fix"
  "IMPROPER_CLASS|improper_|improper" "INTEGRATE_CLASS||integrate" "KSPACE_CLASS||kspace"
  "MINIMIZE_CLASS|min_|minimize" "PAIR_CLASS|pair_|pair"
  "SURFACE_MODEL|surface_model_|surface_model" "NORMAL_MODEL|normal_model_|normal_model"
  "TANGENTIAL_MODEL|tangential_model_|tangential_model" "COHESION_MODEL|cohesion_model_|cohesion_model"
  "ROLLING_MODEL|rolling_model_|rolling_model" "READER_CLASS|reader_|reader" "REGION_CLASS|region_|region"
  "CFD_DATACOUPLING_CLASS|cfd_datacoupling_|cfd_datacoupling"
  "CFD_REGIONMODEL_CLASS|cfd_regionmodel_|cfd_regionmodel" "LB_CLASS||lb"
  "SPH_KERNEL_CLASS|sph_kernel_|sph_kernel" "MESHMODULE_CLASS|mesh_module_|mesh_module"
  "MESHMOVER_CLASS|mesh_mover_|mesh_mover")

set(all_headers ${staged_headers} ${TSG_OVERLAY_HEADERS})
# read every header once
set(header_names "")
foreach(h IN LISTS all_headers)
  get_filename_component(name "${h}" NAME)
  if(name MATCHES "^style_")
    continue()
  endif()
  list(APPEND header_names "${name}")
  file(READ "${h}" "content_${name}")
endforeach()
list(REMOVE_DUPLICATES header_names)
list(SORT header_names)

foreach(row IN LISTS style_table)
  string(REPLACE "|" ";" fields "${row}")
  list(GET fields 0 macro)
  list(GET fields 1 prefix)
  list(GET fields 2 stylename)
  set(text "")
  foreach(name IN LISTS header_names)
    if(prefix STREQUAL "" OR name MATCHES "^${prefix}")
      string(FIND "${content_${name}}" "${macro}" pos)
      if(NOT pos EQUAL -1)
        string(APPEND text "#include \"${name}\"\n")
      endif()
    endif()
  endforeach()
  tsg_write_if_different("${TSG_STAGED_SRC}/style_${stylename}.h" "${text}")
endforeach()

tsg_write_if_different("${TSG_STAGED_SRC}/version_liggghts.h"
  "#define LIGGGHTS_VERSION \"LIGGGHTS-PUBLIC 3.8.0 + tsg-dem ${PROJECT_VERSION}\"\n")

# ---- 4. contact-model combinations: our explicit list ---------------------------------------------
# Collect the model names each kind registers, then check every GRAN_MODEL line against them.
foreach(kind SURFACE NORMAL TANGENTIAL COHESION ROLLING)
  set(known_${kind} "")
  string(TOLOWER "${kind}" lower)
  foreach(name IN LISTS header_names)
    if(name MATCHES "^${lower}_model_")
      string(REGEX MATCHALL "(^|\n)${kind}_MODEL\\(([A-Za-z0-9_]+)," hits "${content_${name}}")
      foreach(hit IN LISTS hits)
        string(REGEX REPLACE ".*${kind}_MODEL\\(([A-Za-z0-9_]+),.*" "\\1" model "${hit}")
        list(APPEND known_${kind} "${model}")
      endforeach()
    endif()
  endforeach()
endforeach()
list(APPEND known_TANGENTIAL TANGENTIAL_OFF)
list(APPEND known_COHESION COHESION_OFF)
list(APPEND known_ROLLING ROLLING_OFF)

set(whitelist_file "${TSG_OVERLAY_DIR}/contact/contact_models.list")
file(STRINGS "${whitelist_file}" whitelist_lines)
set(combinations "")
set(count 0)
foreach(line IN LISTS whitelist_lines)
  string(STRIP "${line}" line)
  if(line STREQUAL "" OR line MATCHES "^#")
    continue()
  endif()
  if(NOT line MATCHES "^GRAN_MODEL\\(([A-Z0-9_]+), *([A-Z0-9_]+), *([A-Z0-9_]+), *([A-Z0-9_]+), *([A-Z0-9_]+)\\)$")
    message(FATAL_ERROR "${whitelist_file}: malformed line '${line}' (expected GRAN_MODEL(NORMAL, TANGENTIAL, COHESION, ROLLING, SURFACE))")
  endif()
  set(parts "${CMAKE_MATCH_1};${CMAKE_MATCH_2};${CMAKE_MATCH_3};${CMAKE_MATCH_4};${CMAKE_MATCH_5}")
  foreach(kind NORMAL TANGENTIAL COHESION ROLLING SURFACE)
    list(POP_FRONT parts model)
    if(NOT model IN_LIST known_${kind})
      message(FATAL_ERROR "${whitelist_file}: '${model}' in '${line}' is not a registered ${kind} model (known: ${known_${kind}})")
    endif()
  endforeach()
  string(APPEND combinations "${line}\n")
  math(EXPR count "${count} + 1")
endforeach()
tsg_write_if_different("${TSG_STAGED_SRC}/style_contact_model.h" "${combinations}")
message(STATUS "Contact-model combinations compiled: ${count} (from ${whitelist_file})")
