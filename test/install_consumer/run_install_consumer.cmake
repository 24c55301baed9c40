# The consumer matrix: find_package(pcl_ddg) from the build tree and from an install into a
# temporary prefix, each by a consumer declared project(x CXX) and project(x C CXX). Every consumer
# is built with the build's compilers and sanitizer flags and run. (pkg-config, from the build tree
# and from a moved install, is test/pkg_config.)
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
macro(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed (${result}): ${ARGN}")
  endif()
endmacro()
step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

foreach(place build_tree install)
  if(place STREQUAL "install")
    set(search_path "${prefix}")
  else()
    set(search_path "${BUILD_DIR}")
  endif()
  foreach(languages "CXX" "C CXX")
    string(REPLACE " " "_" tag "${place}_${languages}")
    set(build "${WORK_DIR}/${tag}")
    message(STATUS "consumer: ${place}, project(x ${languages})")
    step(${CMAKE_COMMAND} -S "${CONSUMER_SOURCE}" -B "${build}" -DCMAKE_PREFIX_PATH=${search_path}
         "-DCONSUMER_LANGUAGES=${languages}" -DCMAKE_BUILD_TYPE=Release
         -DCMAKE_C_COMPILER=${CONSUMER_C_COMPILER} -DCMAKE_CXX_COMPILER=${CONSUMER_CXX_COMPILER}
         "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_FLAGS}")
    step(${CMAKE_COMMAND} --build "${build}")
    step("${build}/consumer")
  endforeach()
endforeach()
