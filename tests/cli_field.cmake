# Solves a one-curve sketch into a .stf, reports its stats, and slices through it; a malformed
# sketch names the curve and point.
file(WRITE ${TMP}/sketch.json [=[
{"domain": {"min": [-16, -16, -4], "max": [16, 16, 4], "shortest_side_cells": 4},
 "curves": [{"points": [[-10, 0, 0], [0, 8, 0], [10, 0, 0]], "plane_normal": [0, 0, 1], "axis": "x"}]}
]=])
execute_process(COMMAND ${ST} field ${TMP}/sketch.json -o ${TMP}/f.stf --json RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "field failed: ${err}")
endif()
string(JSON res GET "${out}" residual)
string(JSON sing GET "${out}" singular_cells)
string(JSON secs GET "${out}" seconds)
if(res GREATER 1e-6)
  message(FATAL_ERROR "residual too large: ${out}")
endif()
execute_process(COMMAND ${ST} exemplar stripes --size 32,32 -o ${TMP}/stripes.png)
execute_process(COMMAND ${ST} analyze ${TMP}/stripes.png --grain x --levels 2 --neighborhood 5 -o ${TMP}/stripes.stx
  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "analyze failed: ${err}")
endif()
execute_process(COMMAND ${ST} slice ${TMP}/stripes.stx --axis z --at 0 --origin -6,-6 --size 12,12 --passes 1
  --field ${TMP}/f.stf -o ${TMP}/fcut.png RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "slice with a .stf field failed: ${err}")
endif()
file(WRITE ${TMP}/bad_sketch.json [=[
{"domain": {"min": [0, 0, 0], "max": [8, 8, 8]}, "curves": [{"points": [[1, 1, 1], [1, 1, 1]], "plane_normal": [0, 0, 1]}]}
]=])
execute_process(COMMAND ${ST} field ${TMP}/bad_sketch.json -o ${TMP}/bad.stf RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "curves\\[0\\]\\.points\\[1\\]: repeats the previous point")
  message(FATAL_ERROR "malformed sketch accepted or unclear: ${err}")
endif()
