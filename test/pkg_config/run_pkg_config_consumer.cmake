# pkg-config without CMake, as a Makefile user would: `c++ main.cpp $(pkg-config --cflags --libs pcl_ddg)`
#   (a) with PKG_CONFIG_PATH at the build folder: the source headers, the generated version.h and
#       the libraries where the build writes them;
#   (b) with an install into a temporary prefix that is then moved to another folder at another
#       depth: the installed .pc finds everything from where it lies (relocatable), and nothing in
#       its flags points back at the source, the build or the prefix it was installed to.
# Each consumer is compiled with the build's compiler and sanitizer flags, linked and run. The flags
# are checked too, so that a copy installed in a default search path cannot make a test pass.
# Scratch files go to a fresh `mktemp -d` folder (concurrent runs never share one), removed on
# success and kept, with its name printed, on failure.
cmake_minimum_required(VERSION 3.19)  # file(REAL_PATH)
foreach(var BUILD_DIR SOURCE_DIR BUILD_TREE_PC_DIR GENERATED_INCLUDE_DIR LIBRARY_DIR
            INSTALL_LIBDIR INSTALL_INCLUDEDIR CONSUMER_SOURCE CONSUMER_CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "run_pkg_config_consumer.cmake: -D${var}=... is missing")
  endif()
endforeach()
find_program(PKG_CONFIG pkg-config REQUIRED)
separate_arguments(sanitize UNIX_COMMAND "${CONSUMER_FLAGS}")
set(original_pkg_config_path "$ENV{PKG_CONFIG_PATH}")

execute_process(COMMAND mktemp -d -t pcl_ddg_pkg_config.XXXXXX OUTPUT_VARIABLE work
                RESULT_VARIABLE result OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT result EQUAL 0 OR NOT IS_DIRECTORY "${work}")
  message(FATAL_ERROR "mktemp -d failed (${result})")
endif()
message(STATUS "scratch folder: ${work}")

function(fail text)
  message(FATAL_ERROR "${text}\n(scratch folder kept: ${work})")
endfunction()

# Runs a command; on failure prints its output and stops.
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT result EQUAL 0)
    fail("failed (${result}): ${ARGN}\n${out}")
  endif()
endfunction()

function(pkg_config out_var)
  execute_process(COMMAND ${PKG_CONFIG} ${ARGN} pcl_ddg OUTPUT_VARIABLE out ERROR_VARIABLE err
                  RESULT_VARIABLE result OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT result EQUAL 0)
    fail("pkg-config ${ARGN} pcl_ddg failed (${result}) with PKG_CONFIG_PATH=$ENV{PKG_CONFIG_PATH}\n${err}")
  endif()
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()

# The folders after -<flag> in a flag list, each made absolute and free of `..` and symlinks.
function(flag_folders out_var flag flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(folders "")
  foreach(f IN LISTS flags)
    if(f MATCHES "^${flag}(.+)$")
      file(REAL_PATH "${CMAKE_MATCH_1}" folder)
      list(APPEND folders "${folder}")
    endif()
  endforeach()
  set(${out_var} "${folders}" PARENT_SCOPE)
endfunction()

# consume(<label> <pc folder> INCLUDES <dirs> LIBDIRS <dirs> FORBIDDEN <folders>)
function(consume label pc_dir)
  cmake_parse_arguments(arg "" "" "INCLUDES;LIBDIRS;FORBIDDEN" ${ARGN})
  message(STATUS "${label}: PKG_CONFIG_PATH=${pc_dir}")
  set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
  if(original_pkg_config_path)
    set(ENV{PKG_CONFIG_PATH} "${pc_dir}:${original_pkg_config_path}")
  endif()

  # The .pc file found is the one in pc_dir, not another in a default search path.
  pkg_config(found_dir --variable=pcfiledir)
  file(REAL_PATH "${found_dir}" found_dir)
  file(REAL_PATH "${pc_dir}" expected_dir)
  if(NOT found_dir STREQUAL expected_dir)
    fail("${label}: pkg-config read pcl_ddg.pc from ${found_dir}, not from ${expected_dir}")
  endif()

  pkg_config(cflags --cflags)
  pkg_config(libs --libs)
  message(STATUS "${label}: --cflags ${cflags}")
  message(STATUS "${label}: --libs ${libs}")
  flag_folders(includes "-I" "${cflags}")
  flag_folders(libdirs "-L" "${libs}")
  foreach(kind INCLUDES LIBDIRS)
    string(TOLOWER "${kind}" found_var)
    foreach(dir IN LISTS arg_${kind})
      file(REAL_PATH "${dir}" dir)
      if(NOT IS_DIRECTORY "${dir}")
        fail("${label}: expected folder ${dir} does not exist")
      endif()
      if(NOT dir IN_LIST ${found_var})
        fail("${label}: pkg-config's flags lack the folder ${dir} (they name: ${${found_var}})")
      endif()
    endforeach()
  endforeach()
  foreach(dir IN LISTS includes libdirs)
    foreach(forbidden IN LISTS arg_FORBIDDEN)
      string(FIND "${dir}/" "${forbidden}/" at)
      if(at EQUAL 0)
        fail("${label}: a flag names ${dir}, inside ${forbidden}")
      endif()
    endforeach()
  endforeach()

  set(program "${work}/${label}_consumer")
  separate_arguments(flags UNIX_COMMAND "${cflags} ${libs}")
  step(${CONSUMER_CXX_COMPILER} -std=c++17 ${sanitize} "${CONSUMER_SOURCE}" ${flags} -o "${program}")
  # LD_LIBRARY_PATH only matters to a shared-library build; the default build links statically.
  set(library_path ${libdirs} $ENV{LD_LIBRARY_PATH})
  string(REPLACE ";" ":" library_path "${library_path}")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "LD_LIBRARY_PATH=${library_path}"
                  "${program}" RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT result EQUAL 0)
    fail("${label}: the consumer failed (${result}):\n${out}")
  endif()
  message(STATUS "${label}: ${out}")
endfunction()

file(REAL_PATH "${SOURCE_DIR}" source_dir)
file(REAL_PATH "${BUILD_DIR}" build_dir)

# (a) The build folder.
consume(build_tree "${BUILD_TREE_PC_DIR}"
  INCLUDES "${SOURCE_DIR}/include" "${GENERATED_INCLUDE_DIR}"
  LIBDIRS "${LIBRARY_DIR}")

# (b) An install, moved after installing.
set(prefix "${work}/prefix")
set(config "")
if(CONFIG)
  set(config --config "${CONFIG}")
endif()
step(${CMAKE_COMMAND} --install "${BUILD_DIR}" ${config} --prefix "${prefix}")
set(moved "${work}/moved/one/level/deeper")
file(MAKE_DIRECTORY "${work}/moved/one/level")
file(RENAME "${prefix}" "${moved}")
consume(moved_install "${moved}/${INSTALL_LIBDIR}/pkgconfig"
  INCLUDES "${moved}/${INSTALL_INCLUDEDIR}"
  LIBDIRS "${moved}/${INSTALL_LIBDIR}"
  FORBIDDEN "${source_dir}" "${build_dir}" "${prefix}")

file(REMOVE_RECURSE "${work}")
