# Runs semap-merge and semap-export on the maps of the split demo and checks their outputs.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}): ${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

# B's frame is the demo's default: B = T_bw * world, so T (B -> A) is its inverse.
set(t_ab "-1.0698091,2.1730362,-0.518,0.9659258,0,0,-0.2588190")
run(${MERGE} ${OUT}/robot_a.smap ${OUT}/robot_b.smap --transform ${t_ab} -o ${OUT}/cli_merged.smap)
if(NOT last_output MATCHES "layers_added 1")
  message(FATAL_ERROR "first merge did not add robot B: ${last_output}")
endif()
run(${MERGE} ${OUT}/cli_merged.smap ${OUT}/robot_b.smap --transform ${t_ab} -o ${OUT}/cli_twice.smap)
if(NOT last_output MATCHES "layers_kept 1")
  message(FATAL_ERROR "second merge changed the map: ${last_output}")
endif()
file(SHA256 ${OUT}/cli_merged.smap once)
file(SHA256 ${OUT}/cli_twice.smap twice)
if(NOT once STREQUAL twice)
  message(FATAL_ERROR "merging the same map twice changed the file")
endif()

run(${EXPORT} ${OUT}/cli_merged.smap --ply ${OUT}/m.ply --pcd ${OUT}/m.pcd --octomap ${OUT}/m.ot
    --png ${OUT}/m_top.png --variance-png ${OUT}/m_var.png)
foreach(f m.ply m.pcd m.ot m_top.png m_var.png)
  file(SIZE ${OUT}/${f} size)
  if(size LESS 1000)
    message(FATAL_ERROR "${f} is only ${size} bytes")
  endif()
endforeach()

# A damaged map is refused, and salvaged only on request.
execute_process(COMMAND ${CMAKE_COMMAND} -E copy ${OUT}/robot_a.smap ${OUT}/cut.smap)
execute_process(COMMAND truncate -s 200000 ${OUT}/cut.smap)
execute_process(COMMAND ${EXPORT} ${OUT}/cut.smap --ply ${OUT}/cut.ply RESULT_VARIABLE rc
                ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "cut.smap: byte offset")
  message(FATAL_ERROR "a truncated map was accepted or the error did not say where: ${err}")
endif()
run(${EXPORT} ${OUT}/cut.smap --salvage --ply ${OUT}/cut.ply)
