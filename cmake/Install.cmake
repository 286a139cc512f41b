# What `cmake --install BUILD` puts where (GNUInstallDirs; the prefix is CMAKE_INSTALL_PREFIX,
# /usr/local unless configured, and --prefix P moves everything that lies under it):
#   bin/skyd, bin/skyctl
#   share/skyd/atmosphere/*.json, share/skyd/weather/*.json    the presets
#   share/skyd/web/                                            the web client
#   etc/skyd/skyd.json            config/skyd.json with the state file in the state directory
#                                 and no web_root (the installed web client)
#   var/lib/skyd/                 the state directory (empty)
#   lib/systemd/system/skyd.service   config/skyd.service with this build's paths
#   lib/python3/dist-packages/skyd_client.py, skyd_png.py      the Python module
#   share/man/man1/skyd.1, skyctl.1, share/man/man5/skyd.json.5
#   share/doc/skyd/README.md, PROTOCOL.md, examples/skyd_timelapse.py
# With the /usr prefix the configuration and state go to /etc/skyd and /var/lib/skyd (the
# FHS); server/cli/install_paths.h is how skyd finds them again.

# A destination under the prefix stays relative, so that `cmake --install --prefix P` moves
# it; one outside it (/etc, /var for the /usr prefix) stays where it is.
function(skyd_install_destination full out)
  string(REGEX REPLACE "/+$" "" prefix "${CMAKE_INSTALL_PREFIX}")
  string(LENGTH "${prefix}/" length)
  string(SUBSTRING "${full}" 0 ${length} head)
  if(head STREQUAL "${prefix}/")
    string(SUBSTRING "${full}" ${length} -1 relative)
    set(${out} "${relative}" PARENT_SCOPE)
  else()
    set(${out} "${full}" PARENT_SCOPE)
  endif()
endfunction()

skyd_install_destination("${SKYD_INSTALL_CONFDIR}" skyd_confdir_destination)
skyd_install_destination("${SKYD_INSTALL_DATADIR}" skyd_datadir_destination)
skyd_install_destination("${SKYD_INSTALL_STATEDIR}" skyd_statedir_destination)

# The Python module goes where Debian's python3 (/usr/bin/python3, not another one first in
# PATH) finds it: /usr/lib/python3/dist-packages for the /usr prefix,
# <prefix>/lib/python3.X/dist-packages for another (/usr/local).
set(skyd_python_default "lib/python3/dist-packages")
if(NOT CMAKE_INSTALL_PREFIX MATCHES "^/usr/*$" AND EXISTS /usr/bin/python3)
  execute_process(COMMAND /usr/bin/python3 -c "import sys; print('%d.%d' % sys.version_info[:2])"
                  OUTPUT_VARIABLE skyd_python_version OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE skyd_python_result)
  if(skyd_python_result EQUAL 0)
    set(skyd_python_default "lib/python${skyd_python_version}/dist-packages")
  endif()
endif()
set(SKYD_INSTALL_PYTHONDIR "${skyd_python_default}" CACHE STRING
    "Where the Python client module is installed (relative: under the prefix)")
set(SKYD_SYSTEMD_UNITDIR "lib/systemd/system" CACHE STRING
    "Where the systemd unit is installed (relative: under the prefix)")

# Text made from a source file by exact replacements, each of which must find its text, so
# that an edit of the source cannot leave a development path in what is installed.
function(skyd_install_text source output)
  file(READ "${source}" text)
  # ARGV, not a list: a replacement may be empty.
  math(EXPR last "${ARGC} - 1")
  foreach(i RANGE 2 ${last} 2)
    math(EXPR j "${i} + 1")
    set(from "${ARGV${i}}")
    set(to "${ARGV${j}}")
    string(FIND "${text}" "${from}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${source} no longer holds \"${from}\", which cmake/Install.cmake "
                          "replaces for the installed copy: update one or the other")
    endif()
    string(REPLACE "${from}" "${to}" text "${text}")
  endforeach()
  file(WRITE "${output}.new" "${text}")
  configure_file("${output}.new" "${output}" COPYONLY)
  set_property(DIRECTORY "${CMAKE_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               "${source}")
endfunction()

set(SKYD_INSTALLED_CONFIG "${CMAKE_BINARY_DIR}/installed/skyd.json")
skyd_install_text("${CMAKE_SOURCE_DIR}/config/skyd.json" "${SKYD_INSTALLED_CONFIG}"
  "  \"web_root\": \"clients/web\",\n" ""
  "\"state_file\": \"var/skyd-state.json\""
  "\"state_file\": \"${SKYD_INSTALL_STATEDIR}/state.json\"")

# config/skyd.service is the unit of a /usr installation (Debian's package).
set(SKYD_INSTALLED_UNIT "${CMAKE_BINARY_DIR}/installed/skyd.service")
skyd_install_text("${CMAKE_SOURCE_DIR}/config/skyd.service" "${SKYD_INSTALLED_UNIT}"
  "ExecStart=/usr/bin/skyd " "ExecStart=${CMAKE_INSTALL_FULL_BINDIR}/skyd "
  "--config /etc/skyd/skyd.json " "--config ${SKYD_INSTALL_CONFDIR}/skyd.json ")

install(TARGETS skyd skyctl RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
install(DIRECTORY config/atmosphere config/weather DESTINATION "${skyd_datadir_destination}"
        FILES_MATCHING PATTERN "*.json")
install(DIRECTORY clients/web/ DESTINATION "${skyd_datadir_destination}/web")
install(FILES "${SKYD_INSTALLED_CONFIG}" DESTINATION "${skyd_confdir_destination}")
install(DIRECTORY DESTINATION "${skyd_statedir_destination}")
install(FILES "${SKYD_INSTALLED_UNIT}" DESTINATION "${SKYD_SYSTEMD_UNITDIR}")
install(FILES clients/python/skyd_client.py clients/python/skyd_png.py
        DESTINATION "${SKYD_INSTALL_PYTHONDIR}")
install(FILES docs/man/skyd.1 docs/man/skyctl.1 DESTINATION "${CMAKE_INSTALL_MANDIR}/man1")
install(FILES docs/man/skyd.json.5 DESTINATION "${CMAKE_INSTALL_MANDIR}/man5")
install(FILES README.md protocol/PROTOCOL.md DESTINATION "${CMAKE_INSTALL_DOCDIR}")
install(PROGRAMS clients/python/skyd_timelapse.py
        DESTINATION "${CMAKE_INSTALL_DOCDIR}/examples")
