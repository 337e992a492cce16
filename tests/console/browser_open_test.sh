#!/bin/bash
# SPDX-License-Identifier: GPL-2.0-or-later
# i20 console opens the page in the desktop's browser through xdg-open when a desktop and a
# terminal are present, handing it a private redirect file, never the token on a command line
# (which every user can read in /proc). A stand-in xdg-open records what it was given; script(1)
# gives the console its terminal.
#
# usage: browser_open_test.sh I20      exit 0 pass, 1 fail, 77 skipped
set -u
I20=${1:?usage: browser_open_test.sh I20}
fail() {
  echo "FAIL: $*"
  exit 1
}
command -v script >/dev/null || { echo "SKIPPED: script(1) is not installed" && exit 77; }
work=$(mktemp -d /tmp/i20-browser-open.XXXXXX)
trap 'rm -rf "$work"' EXIT
mkdir "$work/bin"
cat >"$work/bin/xdg-open" <<STUB
#!/bin/sh
echo "\$*" > "$work/argv"
stat -c %a "\$1" > "$work/mode"
cat "\$1" > "$work/page.part" && mv "$work/page.part" "$work/page"  # whole when it appears
STUB
chmod 755 "$work/bin/xdg-open"

# run_console OPTIONS AWAIT: the console up (its URL printed: the browser is opened right
# after it), then the file AWAIT (the page xdg-open got; 30 s at most), then Ctrl-C.
run_console() {
  rm -f "$work/argv" "$work/page" "$work/mode"
  local up="grep -q token= $work/out" seen="[ -e $2 ]"
  DISPLAY=:99 PATH="$work/bin:$PATH" timeout 90 script -qfec \
    "$I20 --sim console --listen-port 0 $1 & pid=\$!; for i in \$(seq 300); do $up && break; sleep 0.1; done; for i in \$(seq 300); do $seen && break; sleep 0.1; done; kill -INT \$pid; wait \$pid" \
    /dev/null >"$work/out" 2>&1
}

run_console "" "$work/page"
url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/?token=[0-9a-f]*' "$work/out" | head -1)
[[ -n $url ]] || fail "no URL printed: $(cat "$work/out")"
[[ -e $work/page ]] || fail "xdg-open was not started"
grep -qF "url=$url\"" "$work/page" || fail "the page does not lead to $url: $(cat "$work/page")"
token=${url##*=}
grep -q "$token" "$work/argv" && fail "the token is on xdg-open's command line: $(cat "$work/argv")"
[[ $(cat "$work/mode") == 600 ]] || fail "the redirect file is readable by others (mode $(cat "$work/mode"))"
[[ -e $(cat "$work/argv") ]] && fail "the redirect file outlived the console"

run_console "--no-browser" "$work/out" # up is enough: it would have opened right after
[[ -e $work/page ]] && fail "--no-browser still opened the browser"
echo "browser_open_test: passed"
