# solidtex_stage(<name> SOURCES ... [STAGES ...] [PUBLIC_LIBS ...] [PRIVATE_LIBS ...]
#                [TESTS ...] [TEST_STAGES ...])
#
# One pipeline stage of synth/: a static library solidtex_<name> built from the folder's
# sources, linked to the stages it may use (STAGES, named without the prefix), and a test
# executable solidtex_<name>_tests from TESTS. The allowed stage edges are recorded in
# ${CMAKE_BINARY_DIR}/stage_graph.txt (one line per target: name|stages it links|its files), which the layering test (scripts/check-layering.py)
# compares with every #include, so a file cannot reach a stage its target does not link.
function(solidtex_stage name)
  cmake_parse_arguments(S "" "" "SOURCES;STAGES;PUBLIC_LIBS;PRIVATE_LIBS;TESTS;TEST_STAGES" ${ARGN})
  set(target solidtex_${name})
  add_library(${target} STATIC ${S_SOURCES})
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR}/synth)
  set(stage_targets)
  foreach(s IN LISTS S_STAGES)
    list(APPEND stage_targets solidtex_${s})
  endforeach()
  target_link_libraries(${target} PUBLIC ${stage_targets} ${S_PUBLIC_LIBS} PRIVATE ${S_PRIVATE_LIBS})
  string(REPLACE ";" " " deps "${S_STAGES}")
  string(REPLACE ";" " " files "${S_SOURCES}")
  set_property(GLOBAL APPEND PROPERTY SOLIDTEX_STAGE_GRAPH "${name}|${deps}|${files}")
  if(S_TESTS)
    set(test_targets)
    foreach(s IN LISTS S_TEST_STAGES)
      list(APPEND test_targets solidtex_${s})
    endforeach()
    add_executable(${target}_tests ${S_TESTS})
    target_link_libraries(${target}_tests PRIVATE ${target} ${test_targets} GTest::gtest_main)
    string(REPLACE ";" " " tdeps "${S_TEST_STAGES}")
    string(REPLACE ";" " " tfiles "${S_TESTS}")
    set_property(GLOBAL APPEND PROPERTY SOLIDTEX_STAGE_GRAPH "${name}/tests|${name} ${tdeps}|${tfiles}")
    gtest_discover_tests(${target}_tests DISCOVERY_TIMEOUT 60
      PROPERTIES ENVIRONMENT "SOLIDTEX_SHARED=${PROJECT_SOURCE_DIR}/../shared")
  endif()
endfunction()

# Writes the recorded stage graph once every stage is declared.
function(solidtex_write_stage_graph)
  get_property(lines GLOBAL PROPERTY SOLIDTEX_STAGE_GRAPH)
  list(JOIN lines "\n" text)
  file(WRITE ${CMAKE_BINARY_DIR}/stage_graph.txt "${text}\n")
endfunction()
