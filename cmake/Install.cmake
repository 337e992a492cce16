# SPDX-License-Identifier: GPL-2.0-or-later
# What `cmake --install` puts where (GNU layout under CMAKE_INSTALL_PREFIX, /usr/local by
# default, /usr for the Debian package):
#   bin/                                  i20, wpd, rpd, i20sim
#   share/i20tools/profiles/              the shipped motor and tuning profiles (found by name)
#   share/i20tools/motors/                example motor files for `i20sim --motor`
#   share/i20tools/console/               the pages `i20 console` serves (lib/console)
#   share/doc/i20tools/                   README.md, docs/, the profile and simulator notes
#   share/man/man1/                       man pages, generated from --help (packaging/)
#   share/bash-completion/completions/i20 bash completion, generated from --help (packaging/)
# The parameter database and the fault table are compiled into the programs, so params/
# is not installed.
include(GNUInstallDirs)

install(TARGETS i20 wpd rpd i20sim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(DIRECTORY ${PROJECT_SOURCE_DIR}/profiles/ DESTINATION ${CMAKE_INSTALL_DATADIR}/i20tools/profiles
        FILES_MATCHING PATTERN "*.yaml" PATTERN "*.md")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/motors/ DESTINATION ${CMAKE_INSTALL_DATADIR}/i20tools/motors
        FILES_MATCHING PATTERN "*.yaml")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/share/console/ DESTINATION ${CMAKE_INSTALL_DATADIR}/i20tools/console
        FILES_MATCHING PATTERN "*.html" PATTERN "*.js" PATTERN "*.css")

# The same layout as in the repository, so the documents' relative links keep working.
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/docs/README.md ${PROJECT_SOURCE_DIR}/docs/facts.md
              ${PROJECT_SOURCE_DIR}/docs/motor-model.md ${PROJECT_SOURCE_DIR}/docs/axis-tuning.md
              ${PROJECT_SOURCE_DIR}/docs/commissioning-analysis.md ${PROJECT_SOURCE_DIR}/docs/commissioning.md
              ${PROJECT_SOURCE_DIR}/docs/linuxcnc-hal.md ${PROJECT_SOURCE_DIR}/docs/field-messages.md
              ${PROJECT_SOURCE_DIR}/docs/virtual-feedback.md ${PROJECT_SOURCE_DIR}/docs/console.md DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
install(FILES ${PROJECT_SOURCE_DIR}/motors/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}/motors)
install(FILES ${PROJECT_SOURCE_DIR}/profiles/README.md ${PROJECT_SOURCE_DIR}/profiles/TUNING.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/profiles)
install(FILES ${PROJECT_SOURCE_DIR}/lib/sim/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR}/lib/sim)

# Man pages and the completion script are built from the programs' --help (packaging/).
add_subdirectory(${PROJECT_SOURCE_DIR}/packaging ${PROJECT_BINARY_DIR}/packaging)
