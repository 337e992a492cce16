# SPDX-License-Identifier: GPL-2.0-or-later
# Warnings policy. The warnings are always on; turning them into errors is for
# developers and CI (scripts/build, .ci/run pass -DI20_WERROR=ON), not for a packager or a
# user on a newer compiler, whose build must not break on a warning we have not seen yet.
option(I20_WERROR "Treat compiler warnings as errors (developers and CI)" OFF)

add_compile_options(-Wall -Wextra -Wpedantic)
if(I20_WERROR)
  add_compile_options(-Werror)
endif()
