#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The Ansible modules (contrib/ansible) against simulated 8I20s on localhost:
#   1. modules.yml: check mode writes nothing and reports a change, apply reports a change, a
#      second apply reports none, a refused profile fails and writes nothing, facts hold the
#      card's values;
#   2. the shipped example playbook over an inventory of two machines with two simulated
#      axes each: the first run changes every axis, the second changes nothing.
# Usage: run_tests.sh BIN_DIR SOURCE_DIR. Exits 77 (ctest SKIP_RETURN_CODE) without ansible-playbook.
set -euo pipefail
bin=$1
src=$2
if ! command -v ansible-playbook >/dev/null; then
  echo "SKIPPED: ansible-playbook is not installed (Debian: apt-get install ansible-core)"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Nothing from the user running the tests: no parameter overlay, no backups in their home,
# no Ansible configuration or temporary files of theirs.
export XDG_CONFIG_HOME=$work/config XDG_STATE_HOME=$work/state I20_PARAMS= I20_PROFILE_PATH=
: >"$work/ansible.cfg"
export ANSIBLE_CONFIG=$work/ansible.cfg ANSIBLE_LOCAL_TEMP=$work/ansible-tmp ANSIBLE_REMOTE_TEMP=$work/ansible-tmp
export ANSIBLE_LIBRARY=$src/contrib/ansible/library ANSIBLE_NOCOLOR=1 ANSIBLE_RETRY_FILES_ENABLED=0
export ANSIBLE_LOCALHOST_WARNING=0 ANSIBLE_INVENTORY_UNPARSED_WARNING=0 ANSIBLE_PYTHON_INTERPRETER=auto_silent
export PATH=$bin:$PATH  # the example playbook finds i20 on PATH, as on a machine with the package

echo "== modules.yml"
ansible-playbook -i localhost, "$src/tests/ansible/modules.yml" -e "i20=$bin/i20" -e "work=$work"

# Several machines, several axes each: every host is this machine (connection: local).
# The recap counts a looped task once: changed=1 is the apply task having changed an axis.
# (The lathe is not on a 120 V line here: a simulator image with line-120v values powers up at
# its default 320 V bus and latches BUSHIVFAULT before --sim-control lowers the bus.)
cat >"$work/inventory.yml" <<INV
i20_machines:
  vars:
    ansible_connection: local
    i20_backup_dir: $work/fleet-backups
  hosts:
    mill-1:
      i20_axes:
        - {name: x, sim_eeprom: $work/mill-1-x.eeprom, profile: line-240v}
        - {name: y, sim_eeprom: $work/mill-1-y.eeprom, profile: line-240v}
    lathe-1:
      i20_axes:
        - {name: x, sim_eeprom: $work/lathe-1-x.eeprom, profile: line-240v}
        - {name: z, sim_eeprom: $work/lathe-1-z.eeprom, profile: line-240v}
INV
recap() {  # the PLAY RECAP line of host $2 in file $1
  grep -E "^$2 +:" "$1"
}
expect() {  # file host pattern
  if ! recap "$1" "$2" | grep -Eq "$3"; then
    echo "FAILED: $2 expected '$3' in: $(recap "$1" "$2")"
    exit 1
  fi
}
for run in first second; do
  echo "== example playbook, $run run"
  ansible-playbook -i "$work/inventory.yml" "$src/contrib/ansible/playbook.yml" | tee "$work/$run.out"
done
for host in mill-1 lathe-1; do
  expect "$work/first.out" $host 'changed=1 .*failed=0'
  expect "$work/second.out" $host 'changed=0 .*failed=0'
done
[ "$(ls "$work/fleet-backups" | wc -l)" -eq 4 ] || { echo "FAILED: expected 4 backups"; ls "$work/fleet-backups"; exit 1; }
echo "PASSED"
