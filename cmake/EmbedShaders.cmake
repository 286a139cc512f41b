# skyd_embed_shader(<target> NAME <var> SOURCE <file.comp> [DEFINES <D>...])
# Compiles GLSL to SPIR-V with glslangValidator at build time and writes a C header
# <var>.spv.h holding `static const uint32_t <var>_spv[]`, added to <target>'s sources.
# The shared includes are dependencies, so editing one recompiles every shader.
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)

set(SKYD_SHADER_OUT "${CMAKE_BINARY_DIR}/shaders")
file(MAKE_DIRECTORY "${SKYD_SHADER_OUT}")
file(GLOB SKYD_SHADER_INCLUDES CONFIGURE_DEPENDS
     "${CMAKE_SOURCE_DIR}/shaders/include/*.glsl" "${CMAKE_SOURCE_DIR}/shaders/include/*.h")

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
