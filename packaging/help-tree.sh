# SPDX-License-Identifier: GPL-2.0-or-later
# Reads the command tree of a CLI11 program from its --help output, so the man pages and
# the bash completion are generated from the programs themselves and cannot miss a
# subcommand or an option. Sourced by gen-man-pages and gen-completion.
#
# CLI11 prints, per command: a description, "Usage: ...", then sections "Positionals:",
# "Options:" (also indented inside "[Option Group: ...]") and "Subcommands:", each entry
# indented, the name first. An option that takes a value shows its type right after its
# names ("--port TEXT", "--to TEXT:{nv,working,both}"); a flag shows none, or only
# "Needs:"/"Excludes:" notes.

# help_text WORD... : the --help output of the command WORD... (e.g. i20 profile apply).
help_text() {
  "$@" --help 2>&1
}

# help_subcommands WORD... : one line per subcommand, "NAME<TAB>DESCRIPTION".
help_subcommands() {
  help_text "$@" | awk '
    /^Subcommands:/ { in_section = 1; next }
    in_section && /^[^ ]/ { in_section = 0 }
    in_section && /^  [a-z]/ {
      name = $1
      sub(/^  [^ ]+ +/, "")
      printf "%s\t%s\n", name, $0
    }'
}

# help_options WORD... : one line per option name, "NAME<TAB>KIND" where KIND is flag,
# value, or the choices of a value "{nv,working,both}".
help_options() {
  help_text "$@" | awk '
    /^[^ ]/ { section = $0 }
    section ~ /^(Options:|\[Option Group)/ && /^ +-/ {
      names = $1
      kind = "flag"
      if (NF >= 2 && $2 ~ /^[A-Z][A-Z_]*(:.*)?$/ && $2 !~ /^[A-Z][a-z]/) kind = "value"
      if (kind == "value" && match($2, /:\{[^}]*\}/)) kind = substr($2, RSTART + 1, RLENGTH - 1)
      n = split(names, list, ",")
      for (i = 1; i <= n; i++) if (list[i] ~ /^-/) printf "%s\t%s\n", list[i], kind
    }'
}

# help_tree WORD... : every command path below WORD..., one per line, depth first
# ("get", "profile", "profile apply", ...).
help_tree() {
  local name _
  while IFS=$'\t' read -r name _; do
    [ -n "$name" ] || continue
    echo "${HELP_TREE_PREFIX:+$HELP_TREE_PREFIX }$name"
    HELP_TREE_PREFIX="${HELP_TREE_PREFIX:+$HELP_TREE_PREFIX }$name" help_tree "$@" "$name"
  done < <(help_subcommands "$@")
}
