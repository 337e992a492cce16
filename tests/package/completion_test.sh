#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Usage: completion_test.sh COMPLETION_FILE I20 SOURCE_DIR
# Drives the completion function the way bash does (COMP_WORDS/COMP_CWORD) and compares
# what it offers with what the program's --help lists.
set -uo pipefail
completion=$1 i20=$2 src=$3
source "$src/packaging/help-tree.sh"
[ -f "$completion" ] || { echo "FAIL: $completion was not generated (build the i20_completion target)"; exit 1; }
source "$completion"
export PATH="$(dirname "$i20"):$PATH"
failures=0 checks=0

complete_words() {  # complete_words WORD... : what _i20 offers for the last word
  COMP_WORDS=("$@")
  COMP_CWORD=$((${#COMP_WORDS[@]} - 1))
  COMPREPLY=()
  _i20
  printf '%s\n' "${COMPREPLY[@]}"
}

expect() {  # expect WHAT OFFERED WORD...
  local what=$1 offered=$2 w
  shift 2
  for w in "$@"; do
    checks=$((checks + 1))
    if ! grep -qxF -- "$w" <<<"$offered"; then
      echo "FAIL: $what: '$w' not offered"
      failures=$((failures + 1))
    fi
  done
}

while IFS= read -r path; do
  # shellcheck disable=SC2206
  words=($path)
  subs=$(help_subcommands i20 "${words[@]}" | cut -f1)
  # shellcheck disable=SC2086
  [ -z "$subs" ] || expect "i20 $path <TAB>" "$(complete_words i20 "${words[@]}" "")" $subs
  opts=$(help_options i20 "${words[@]}" | cut -f1)
  # shellcheck disable=SC2086
  expect "i20 $path -<TAB>" "$(complete_words i20 "${words[@]}" -)" $opts
  while IFS=$'\t' read -r opt kind; do
    [[ $kind == \{*\} ]] || continue
    kind=${kind#\{}
    kind=${kind%\}}
    # shellcheck disable=SC2086
    expect "i20 $path $opt <TAB>" "$(complete_words i20 "${words[@]}" "$opt" "")" ${kind//,/ }
  done < <(help_options i20 "${words[@]}")
done < <(echo; help_tree i20)

# Names: parameters (any case), profiles by name from the search path, NAME= for set.
expect "i20 get NVMAXC<TAB>" "$(complete_words i20 get NVMAXC)" NVMAXCURRENT
expect "i20 get busv<TAB>" "$(complete_words i20 get busv)" BUSV
expect "i20 --sim get NVKQ<TAB>" "$(complete_words i20 --sim get NVKQ)" NVKQP NVKQI NVKQIL
expect "i20 set NVBRAKEON<TAB>" "$(complete_words i20 set NVBRAKEON)" NVBRAKEONV=
expect "i20 --port X profile apply line-1<TAB>" \
  "$(I20_PROFILE_PATH=$src/profiles complete_words i20 --port X profile apply line-1)" line-120v
for p in "$src"/profiles/*.yaml; do
  name=${p##*/}
  expect "i20 profile export <TAB>" "$(I20_PROFILE_PATH=$src/profiles complete_words i20 profile export "")" \
    "${name%.yaml}"
done
# An option's value is not mistaken for a subcommand: "--port profile" stays at the top.
expect "i20 --port dump <TAB>" "$(complete_words i20 --port dump "")" info profile

echo "$checks checks, $failures failures"
[ "$failures" -eq 0 ]
