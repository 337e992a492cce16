# SPDX-License-Identifier: GPL-2.0-or-later
# A Debian package (cpack -G DEB) of what Install.cmake installs.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DCMAKE_INSTALL_PREFIX=/usr
#   cmake --build build-release && (cd build-release && cpack -G DEB)
# Dependencies come from dpkg-shlibdeps (dpkg-dev) on the installed programs, so the package
# needs exactly the shared libraries the build linked (libyaml-cpp, libstdc++, ...).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME i20tools)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "i20tools")
set(CPACK_PACKAGE_CONTACT "i20tools maintainers <i20tools@example.invalid>")
# The first line of the Debian description; CPACK_PACKAGE_DESCRIPTION is the rest.
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "set up Mesa 8I20 servo amplifiers (LBP over RS-422 or Ethernet)")
# Debian wants the extended description's lines at most 80 columns (lintian
# extended-description-line-too-long): these are wrapped at 72.
set(CPACK_PACKAGE_DESCRIPTION
    "i20tools reads and writes the working and EEPROM parameters of Mesa\n"
    "8I20 servo amplifiers by name, decodes and clears their faults, tunes\n"
    "the current loop and applies one motor profile to many amplifiers,\n"
    "over an RS-422 adapter or through a 7I96S/7I92T Ethernet card. It\n"
    "includes drop-in wpd/rpd replacements for Mesa's WPD/RPD, exports\n"
    "profiles as LinuxCNC HAL setp lines, and ships a strict simulator of\n"
    "the card (i20sim) for trying everything without hardware.")
string(REPLACE ";" "" CPACK_PACKAGE_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION}")
set(CPACK_PACKAGE_INSTALL_DIRECTORY i20tools)
# The license: GPL-2.0-or-later. A Debian control file has no license field; the package
# states it in /usr/share/doc/i20tools/copyright (DEP-5, packaging/debian/copyright). The
# generators that have a field or a license page get it here.
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_RPM_PACKAGE_LICENSE GPL-2.0-or-later)
set(CPACK_STRIP_FILES ON)

set(CPACK_DEBIAN_PACKAGE_NAME i20tools)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # i20tools_VERSION_ARCH.deb
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${CPACK_PACKAGE_CONTACT}")
set(CPACK_DEBIAN_PACKAGE_SECTION electronics)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Placeholder: the project's public home page, once it has one.
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://example.invalid/i20tools")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The completion and man pages are only useful with these; neither is required.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "bash-completion, mesaflash, linuxcnc-uspace")

include(CPack)
