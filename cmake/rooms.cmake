# The rooms of jsatlas and which rooms each one stands on (docs/README.md, "the rooms").
# One table, read by CMakeLists.txt (one static library per room, linked to the
# rooms listed here) and by cmake/check_layering.cmake (an #include of a room
# outside this list, direct or through the rooms it stands on, fails the build).
# jsatlas_room_dir_<room>: its folder (its own files only, not sub-folders);
# jsatlas_room_uses_<room>: the rooms it stands on, direct edges only: a room may
# use them and everything below them.
set(jsatlas_rooms engine geometry io losses metrics model heuristics tool baselines pictures)
set(jsatlas_room_dir_engine     engine)
set(jsatlas_room_dir_geometry   io/geometry)
set(jsatlas_room_dir_io         io)
set(jsatlas_room_dir_losses     losses)
set(jsatlas_room_dir_metrics    losses/metrics)
set(jsatlas_room_dir_model      model)
set(jsatlas_room_dir_heuristics model/heuristics)
set(jsatlas_room_dir_tool       model/tool)
set(jsatlas_room_dir_baselines  model/baselines)
set(jsatlas_room_dir_pictures   io/pictures)

set(jsatlas_room_uses_engine)
set(jsatlas_room_uses_geometry   engine)
set(jsatlas_room_uses_io         geometry)
set(jsatlas_room_uses_losses     geometry metrics)
set(jsatlas_room_uses_metrics    geometry)
set(jsatlas_room_uses_model      losses)
set(jsatlas_room_uses_heuristics model)
set(jsatlas_room_uses_tool       io metrics heuristics)
set(jsatlas_room_uses_baselines  tool)
set(jsatlas_room_uses_pictures   tool)

# jsatlas_room_closure(<room> <out-var>): every room <room> may use, itself excluded,
# in the order of jsatlas_rooms.
function(jsatlas_room_closure room out)
  set(seen)
  set(todo ${jsatlas_room_uses_${room}})
  while(todo)
    list(POP_FRONT todo r)
    if(NOT r IN_LIST seen)
      list(APPEND seen ${r})
      list(APPEND todo ${jsatlas_room_uses_${r}})
    endif()
  endwhile()
  set(ordered)
  foreach(r ${jsatlas_rooms})
    if(r IN_LIST seen)
      list(APPEND ordered ${r})
    endif()
  endforeach()
  set(${out} ${ordered} PARENT_SCOPE)
endfunction()

# jsatlas_room_of(<path> <out-var>): the room a header path such as
# "io/geometry/mesh.h" belongs to, or "" if it lies in no room (bin/, test/, ...).
function(jsatlas_room_of path out)
  get_filename_component(dir ${path} DIRECTORY)
  set(found "")
  foreach(r ${jsatlas_rooms})
    if(dir STREQUAL "${jsatlas_room_dir_${r}}")
      set(found ${r})
    endif()
  endforeach()
  set(${out} "${found}" PARENT_SCOPE)
endfunction()
