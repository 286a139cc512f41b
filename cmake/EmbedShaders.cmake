# skyd_embed_shader(<target> NAME <var> SOURCE <file.comp> [DEFINES <D>...])
# Compiles GLSL to SPIR-V with glslangValidator at build time and writes a C header
# <var>.spv.h holding `static const uint32_t <var>_spv[]`, added to <target>'s sources.
# The shared includes are dependencies, so editing one recompiles every shader.
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)

set(SKYD_SHADER_OUT "${CMAKE_BINARY_DIR}/shaders")
file(MAKE_DIRECTORY "${SKYD_SHADER_OUT}")
file(GLOB SKYD_SHADER_INCLUDES CONFIGURE_DEPENDS
     "${CMAKE_SOURCE_DIR}/shaders/include/*.glsl" "${CMAKE_SOURCE_DIR}/shaders/include/*.h"
     "${CMAKE_SOURCE_DIR}/tests/shaders/*.glsl")

function(skyd_embed_shader target)
  cmake_parse_arguments(ARG "" "NAME;SOURCE" "DEFINES" ${ARGN})
  set(header "${SKYD_SHADER_OUT}/${ARG_NAME}.spv.h")
  set(defines "")
  foreach(d IN LISTS ARG_DEFINES)
    list(APPEND defines "-D${d}")
  endforeach()
  add_custom_command(
    OUTPUT "${header}"
    COMMAND "${GLSLANG_VALIDATOR}" -V --target-env vulkan1.2 --quiet
            -I${CMAKE_SOURCE_DIR}/shaders/include ${defines}
            --vn ${ARG_NAME}_spv -o "${header}.tmp" "${ARG_SOURCE}"
    COMMAND ${CMAKE_COMMAND} -DIN=${header}.tmp -DOUT=${header}
            -P "${CMAKE_SOURCE_DIR}/cmake/StaticSpirv.cmake"
    DEPENDS "${ARG_SOURCE}" ${SKYD_SHADER_INCLUDES} "${CMAKE_SOURCE_DIR}/cmake/StaticSpirv.cmake"
    COMMENT "glslangValidator ${ARG_NAME}"
    VERBATIM)
  target_sources(${target} PRIVATE "${header}")
endfunction()

# skyd_embed_shader_list(<room> <target> <list file>): every SKY_SHADER(room, name, source,
# define) line of the list whose room matches, compiled into <target>, and a header
# <room>_shaders.h in SKYD_SHADER_OUT that includes their SPIR-V.
function(skyd_embed_shader_list room target list)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${list}")
  file(STRINGS "${list}" lines REGEX "^SKY_SHADER\\(")
  set(header "/* Generated from shaders/shaders.def: the SPIR-V of the ${room} shaders. */\n")
  foreach(line IN LISTS lines)
    if(NOT line MATCHES "^SKY_SHADER\\(([a-z]+), ([a-z_]+), ([a-z_]+), ([A-Z_]+)\\)$")
      message(FATAL_ERROR "${list}: cannot read \"${line}\"")
    endif()
    if(NOT CMAKE_MATCH_1 STREQUAL room)
      continue()
    endif()
    set(name ${CMAKE_MATCH_2})
    set(source "${CMAKE_SOURCE_DIR}/shaders/${CMAKE_MATCH_3}.comp")
    if(CMAKE_MATCH_4 STREQUAL "NONE")
      skyd_embed_shader(${target} NAME ${name} SOURCE "${source}")
    else()
      skyd_embed_shader(${target} NAME ${name} SOURCE "${source}" DEFINES ${CMAKE_MATCH_4})
    endif()
    string(APPEND header "#include \"${name}.spv.h\"\n")
  endforeach()
  file(CONFIGURE OUTPUT "${SKYD_SHADER_OUT}/${room}_shaders.h" CONTENT "${header}")
endfunction()
