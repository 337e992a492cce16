#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Usage: debian_files_test.sh BUILD_DIR I20 SOURCE_DIR VERSION
# What lintian would say about the package's generated and hand-written Debian files,
# checked without building the .deb (scripts/package runs lintian itself on the .deb):
#   - a man page for every program and every `i20` subcommand in --help, each with section 1
#     in its .TH line (lintian wrong-manual-section), titled after its file, and a NAME line
#     "i20\-clear\-faults \- description" that man's whatis parser (lexgrog) reads back;
#   - the copyright file is machine-readable (DEP-5): the format URI, a "Files: *" paragraph
#     with Copyright and License, a stand-alone paragraph for every license it names, and the
#     GPL pointed to in /usr/share/common-licenses rather than copied;
#   - the changelog's newest entry is this version, and its .gz is the source compressed
#     reproducibly (gzip -n: no file name, no time stamp).
# Exit 77 (skipped) when help2man is not installed, so no man pages were generated.
set -uo pipefail
build=$1 i20=$2 src=$3 version=$4
source "$src/packaging/help-tree.sh"
export PATH="$(dirname "$i20"):$PATH"
man_dir=$build/packaging/man/man1
failures=0 checks=0
check() {  # check DESCRIPTION COMMAND...
  checks=$((checks + 1))
  if ! "${@:2}"; then
    echo "FAIL: $1"
    failures=$((failures + 1))
  fi
}

# ---------------------------------------------------------------- man pages
if [ ! -d "$man_dir" ] && ! command -v help2man >/dev/null; then
  echo "SKIP: help2man is not installed, so no man pages were generated"
  exit 77
fi
# page_ok NAME: NAME.1.gz has ".TH UPPER-NAME "1"" and a NAME line for NAME.
page_ok() {
  local name=$1 page=$man_dir/$1.1.gz text th whatis
  [ -f "$page" ] || { echo "  $page is missing"; return 1; }
  text=$(zcat "$page") || return 1
  th=$(grep -m1 '^\.TH ' <<<"$text")
  [ "$th" = ".TH ${name^^} \"1\" ${th#.TH ${name^^} \"1\" }" ] ||
    { echo "  $name: .TH line is '$th', want '.TH ${name^^} \"1\" ...'"; return 1; }
  whatis=$(awk '/^\.SH NAME/ { getline; print; exit }' <<<"$text")
  [[ $whatis == "${name//-/\\-} \\- "?* ]] ||
    { echo "  $name: NAME line is '$whatis', want '${name//-/\\-} \\- description'"; return 1; }
  # The description starts lower case, as whatis entries do, unless with an acronym.
  [[ ${whatis#* \\- } =~ ^([a-z0-9]|[A-Z][A-Z0-9]) ]] ||
    { echo "  $name: NAME description starts '${whatis#* \\- }'"; return 1; }
  if command -v lexgrog >/dev/null; then
    [[ $(lexgrog "$page") == *": \"$name - "?*'"' ]] ||
      { echo "  $name: lexgrog reads '$(lexgrog "$page")'"; return 1; }
  fi
}
pages=0
for p in i20 wpd rpd i20sim; do
  check "man page $p.1" page_ok "$p"
  pages=$((pages + 1))
done
while IFS= read -r path; do
  check "man page of 'i20 $path'" page_ok "i20-${path// /-}"
  pages=$((pages + 1))
done < <(help_tree i20)
# No stale pages of subcommands that no longer exist.
check "$pages man pages generated, as many as programs and subcommands" \
  test "$(find "$man_dir" -name '*.1.gz' | wc -l)" -eq "$pages"

# ---------------------------------------------------------------- copyright (DEP-5)
copyright=$src/packaging/debian/copyright
# field PARAGRAPH_NUMBER NAME: the first line of field NAME in paragraph N (1-based).
field() {
  awk -v want="$1" -v name="$2" '
    BEGIN { n = 1 }
    /^[ \t]*$/ { if (seen) n++; seen = 0; next }
    { seen = 1 }
    n == want && index($0, name ":") == 1 { sub(/^[^:]*:[ \t]*/, ""); print; exit }' "$copyright"
}
paragraphs=$(awk '/^[ \t]*$/ { if (seen) n++; seen = 0; next } { seen = 1 } END { print n + seen }' "$copyright")
check "copyright: the DEP-5 format URI" \
  test "$(field 1 Format)" = "https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/"
check "copyright: Upstream-Name i20tools" test "$(field 1 Upstream-Name)" = i20tools
files_star=0
declare -A used=() defined=()
for ((i = 2; i <= paragraphs; i++)); do
  files=$(field "$i" Files) license=$(field "$i" License)
  if [ -n "$files" ]; then
    [ "$files" != "*" ] || files_star=1
    check "copyright: paragraph $i (Files: $files) has Copyright" test -n "$(field "$i" Copyright)"
    check "copyright: paragraph $i (Files: $files) has License" test -n "$license"
    [ -z "$license" ] || used[$license]=1
  elif [ -n "$license" ]; then
    defined[$license]=1
  else
    check "copyright: paragraph $i is neither Files nor License" false
  fi
done
check "copyright: a 'Files: *' paragraph" test "$files_star" = 1
check "copyright: the toolkit is GPL-2+" test "${used[GPL-2+]:-}" = 1
for l in "${!used[@]}"; do check "copyright: a License paragraph for $l" test "${defined[$l]:-}" = 1; done
check "copyright: points to /usr/share/common-licenses/GPL-2" grep -q '/usr/share/common-licenses/GPL-2' "$copyright"
check "copyright: does not copy the GPL's text (lintian copyright-file-contains-full-gpl-license)" \
  bash -c '! grep -q "TERMS AND CONDITIONS FOR COPYING" "$1"' _ "$copyright"
check "copyright: no tabs, continuation lines indented by one space" \
  bash -c '! grep -qP "\t|^ {2,}\S" "$1"' _ "$copyright"

# ---------------------------------------------------------------- changelog
changelog=$src/packaging/debian/changelog
newest=$(sed -n '1s/^i20tools (\([^)]*\)) .*/\1/p' "$changelog")
check "changelog: the newest entry is i20tools $version (got '$newest')" test "$newest" = "$version"
if command -v dpkg-parsechangelog >/dev/null; then
  check "changelog: dpkg-parsechangelog reads version $version" \
    test "$(dpkg-parsechangelog -l "$changelog" -S Version 2>&1)" = "$version"
fi
check "changelog: no change line over 80 columns (lintian debian-changelog-line-too-long)" \
  bash -c '! grep -q "^  .\{79\}" "$1"' _ "$changelog"
gz=$build/packaging/debian/changelog.gz
check "changelog.gz is the source compressed" cmp -s <(zcat "$gz") "$changelog"
# gzip header: byte 3 is the flags (0x08 = a file name follows), bytes 4-7 the time stamp.
check "changelog.gz holds no file name and no time stamp (gzip -n)" \
  test "$(od -An -tx1 -j3 -N5 "$gz" | tr -d ' \n')" = 0000000000

echo "$checks checks, $failures failures"
[ "$failures" -eq 0 ]
