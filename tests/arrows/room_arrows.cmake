# Checks the rooms' arrows (rooms.cmake) with each room's real compile context: its include
# directories (less the compiler's own, IMPLICIT_INCLUDES, as CMake leaves them out), compile
# definitions and options as CMake hands them to its sources (written by tests/CMakeLists.txt
# into CONTEXT_DIR), the C standard and the build type's flags (C_FLAGS). For every room it
# compiles one-line translation units:
#   - its own public header, and the public header of every room it sees: must compile;
#   - the internal header of every room it sees: must fail, the header not found;
#   - the public header of every room it does not see: must fail, the header not found.
# The ones that must compile show that a failure is the missing arrow, not a broken probe.
#   cmake -DSOURCE_DIR=... -DCONTEXT_DIR=... -DWORK_DIR=... -DCOMPILER=... -DC_FLAGS=...
#         -DIMPLICIT_INCLUDES=DIR|DIR... -P room_arrows.cmake
cmake_minimum_required(VERSION 3.20)
foreach(input SOURCE_DIR CONTEXT_DIR WORK_DIR COMPILER)
  if(NOT DEFINED ${input})
    message(FATAL_ERROR "room_arrows.cmake needs -D${input}=...")
  endif()
endforeach()
include("${CMAKE_CURRENT_LIST_DIR}/rooms.cmake")
string(REPLACE "|" ";" implicit_includes "${IMPLICIT_INCLUDES}")

# The compile context of a room's library, as compiler arguments.
function(room_context room out)
  set(target ${SKYD_ROOM_${room}_TARGET})
  separate_arguments(args UNIX_COMMAND "${C_FLAGS}")
  foreach(property INCLUDE_DIRECTORIES COMPILE_DEFINITIONS COMPILE_OPTIONS)
    set(file "${CONTEXT_DIR}/${target}.${property}")
    if(NOT EXISTS "${file}")
      message(FATAL_ERROR "no compile context for ${target}: ${file} (tests/CMakeLists.txt)")
    endif()
    file(STRINGS "${file}" items)
    foreach(item IN LISTS items)
      if(property STREQUAL "INCLUDE_DIRECTORIES")
        if(NOT item IN_LIST implicit_includes)
          list(APPEND args "-I${item}")
        endif()
      elseif(property STREQUAL "COMPILE_DEFINITIONS")
        list(APPEND args "-D${item}")
      else()
        list(APPEND args "${item}")
      endif()
    endforeach()
  endforeach()
  set(${out} "${args}" PARENT_SCOPE)
endfunction()

set(failures "")
set(compiled 0)
set(refused 0)

# Compiles `#include "<header's name>"` in the room's context; expect: COMPILES or NOT_FOUND.
function(probe room header expect)
  if(NOT EXISTS "${SOURCE_DIR}/${header}")
    message(FATAL_ERROR "rooms.cmake names ${header}, which does not exist")
  endif()
  get_filename_component(name "${header}" NAME)
  string(REPLACE "." "_" stem "${name}")
  set(source "${WORK_DIR}/${room}_includes_${stem}.c")
  file(WRITE "${source}" "#include \"${name}\"\nint room_arrows_probe;\n")
  execute_process(COMMAND "${COMPILER}" ${context_${room}} -fsyntax-only "${source}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE output ERROR_VARIABLE output)
  string(REPLACE "." "\\." quoted "${name}")
  set(case "${room} (${SKYD_ROOM_${room}_TARGET}) including ${header}")
  if(expect STREQUAL "COMPILES")
    if(rc EQUAL 0)
      math(EXPR n "${compiled} + 1")
      set(compiled ${n} PARENT_SCOPE)
      return()
    endif()
    set(why "must compile, but:\n${output}")
  elseif(NOT rc EQUAL 0 AND output MATCHES "${quoted}: No such file or directory|'${quoted}' file not found")
    math(EXPR n "${refused} + 1")
    set(refused ${n} PARENT_SCOPE)
    return()
  elseif(rc EQUAL 0)
    set(why "must not compile (no arrow allows it), but did")
  else()
    set(why "must fail with the header not found, but:\n${output}")
  endif()
  set(failures "${failures}${case} ${why}\n" PARENT_SCOPE)
endfunction()

file(MAKE_DIRECTORY "${WORK_DIR}")
foreach(room IN LISTS SKYD_ROOMS)
  room_context(${room} context_${room})
endforeach()

foreach(room IN LISTS SKYD_ROOMS)
  probe(${room} ${SKYD_ROOM_${room}_PUBLIC} COMPILES)
  foreach(other IN LISTS SKYD_ROOMS)
    if(other STREQUAL room)
      continue()
    endif()
    if(other IN_LIST SKYD_ROOM_${room}_SEES)
      probe(${room} ${SKYD_ROOM_${other}_PUBLIC} COMPILES)
      if(SKYD_ROOM_${other}_INTERNAL)
        probe(${room} ${SKYD_ROOM_${other}_INTERNAL} NOT_FOUND)
      endif()
    else()
      probe(${room} ${SKYD_ROOM_${other}_PUBLIC} NOT_FOUND)
    endif()
  endforeach()
endforeach()

if(failures)
  message(FATAL_ERROR "room arrows broken:\n${failures}")
endif()
message(STATUS "room arrows: ${compiled} includes along the arrows compile, ${refused} across "
               "them find no header")
