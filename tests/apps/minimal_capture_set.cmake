# cmake -P script: a capture set as a real robot would export it, by hand: only left.png,
# right.png and camera.yaml per view (docs/capture-format.md), copied from a simulated set.
#   SRC  a capture set (directories with camera.yaml)
#   DST  the minimal set to write
file(REMOVE_RECURSE "${DST}")
file(GLOB views LIST_DIRECTORIES true "${SRC}/*")
foreach(view ${views})
  if(EXISTS "${view}/camera.yaml")
    get_filename_component(name "${view}" NAME)
    file(MAKE_DIRECTORY "${DST}/${name}")
    foreach(f left.png right.png camera.yaml)
      file(COPY "${view}/${f}" DESTINATION "${DST}/${name}")
    endforeach()
  endif()
endforeach()
