# Solves a one-curve sketch into a .stf, checks its stats, and slices through it; a malformed
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
string(JSON curves GET "${out}" curves)
string(JSON spacing GET "${out}" spacing)
string(JSON nodes GET "${out}" nodes)
string(JSON constrained GET "${out}" constrained_nodes)
string(JSON scale_points GET "${out}" scale_points)
string(JSON nx GET "${out}" dims 0)
string(JSON ny GET "${out}" dims 1)
string(JSON nz GET "${out}" dims 2)
if(res LESS 0 OR res GREATER 1e-6)
  message(FATAL_ERROR "residual not in [0, 1e-6]: ${out}")
endif()
# The 32 x 32 x 8 domain with 4 cells along its shortest side: spacing 2, 17 x 17 x 5 nodes.
if(NOT spacing EQUAL 2 OR NOT nx EQUAL 17 OR NOT ny EQUAL 17 OR NOT nz EQUAL 5)
  message(FATAL_ERROR "expected spacing 2 and dims 17 x 17 x 5: ${out}")
endif()
math(EXPR want_nodes "${nx} * ${ny} * ${nz}")
if(NOT nodes EQUAL want_nodes)
  message(FATAL_ERROR "nodes ${nodes} != ${nx} x ${ny} x ${nz}: ${out}")
endif()
# One curve and no scale constraints; the curve pins some nodes, not all; one smooth arc leaves
# the field without singular cells.
if(NOT curves EQUAL 1 OR NOT scale_points EQUAL 0 OR constrained LESS 1 OR NOT constrained LESS nodes
   OR NOT sing EQUAL 0)
  message(FATAL_ERROR "implausible field stats: ${out}")
endif()
if(NOT secs GREATER 0)
  message(FATAL_ERROR "field seconds ${secs} not positive: ${out}")
endif()
execute_process(COMMAND ${ST} exemplar stripes --size 32,32 -o ${TMP}/stripes.png RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "exemplar failed: ${err}")
endif()
execute_process(COMMAND ${ST} analyze ${TMP}/stripes.png --grain x --levels 2 --neighborhood 5 -o ${TMP}/stripes.stx
  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "analyze failed: ${err}")
endif()
execute_process(COMMAND ${ST} slice ${TMP}/stripes.stx --axis z --at 0 --origin -6,-6 --size 12,12 --passes 1
  --field ${TMP}/f.stf -o ${TMP}/fcut.png --stats ${TMP}/fcut.json RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "slice with a .stf field failed: ${err}")
endif()
file(READ ${TMP}/fcut.json stats)
string(JSON described GET "${stats}" field)
if(NOT described STREQUAL "grid:${nx}x${ny}x${nz}")
  message(FATAL_ERROR "the slice's field is '${described}', not the solved ${nx}x${ny}x${nz} grid")
endif()
# The field turns the stripes: the same cut without it differs.
execute_process(COMMAND ${ST} slice ${TMP}/stripes.stx --axis z --at 0 --origin -6,-6 --size 12,12 --passes 1
  -o ${TMP}/icut.png RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "slice without a field failed: ${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${TMP}/fcut.png ${TMP}/icut.png RESULT_VARIABLE same)
if(same EQUAL 0)
  message(FATAL_ERROR "the .stf field changed nothing in the slice")
endif()
file(WRITE ${TMP}/bad_sketch.json [=[
{"domain": {"min": [0, 0, 0], "max": [8, 8, 8]}, "curves": [{"points": [[1, 1, 1], [1, 1, 1]], "plane_normal": [0, 0, 1]}]}
]=])
execute_process(COMMAND ${ST} field ${TMP}/bad_sketch.json -o ${TMP}/bad.stf RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "curves\\[0\\]\\.points\\[1\\]: repeats the previous point")
  message(FATAL_ERROR "malformed sketch accepted or unclear: ${err}")
endif()
