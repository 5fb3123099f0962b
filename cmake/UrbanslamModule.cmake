# urbanslam_module(NAME SOURCES ... DEPENDS ...): one static library per module,
# headers under include/urbanslam/<NAME>/, exported as urbanslam::<NAME>.
function(urbanslam_module name)
  cmake_parse_arguments(M "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  set(target urbanslam_${name})
  if(M_SOURCES)
    add_library(${target} STATIC ${M_SOURCES})
    target_include_directories(${target} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(${target} PUBLIC ${M_DEPENDS} PRIVATE ${M_PRIVATE_DEPENDS})
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  else()
    # A home for a module that has no code yet: headers only, wired into the graph.
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(${target} INTERFACE ${M_DEPENDS})
  endif()
  add_library(urbanslam::${name} ALIAS ${target})
endfunction()
