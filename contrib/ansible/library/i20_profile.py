# SPDX-License-Identifier: GPL-2.0-or-later
# An Ansible module over `i20 --json profile apply`: every rule, the backup, the verified
# writes and the rollback stay in the i20 program; this module only maps its JSON to a task.

DOCUMENTATION = r"""
---
module: i20_profile
short_description: Apply a motor profile to one Mesa 8I20 servo amplifier
description:
  - Runs C(i20 --json profile apply) on the managed host against one 8I20, reached over a
    serial RS-422 adapter in setup mode, over Ethernet through a 7I96S/7I92T (C(eth://) URL),
    or as an i20 simulator card (for tests).
  - The i20 program does all the work; this module never talks to the card itself. It
    validates the profile against the card and the manual's cross-parameter rules, backs the
    card's values up, writes only the cells that differ, reads every one back, and restores the
    backup on any failure.
  - Idempotent. The task reports C(changed=false) when the card already holds every value of
    the profile (i20's NOTHING TO DO), and nothing is written then.
  - Check mode runs the transaction's dry run (C(--dry-run)). The card is read and the plan is
    made, and nothing is written. C(changed) says whether a real run would write.
  - Diff mode returns the before and after of each cell the run writes (or would write).
  - The task fails when i20 refuses the profile (a safety rule, nothing written), when the card
    cannot be reached, when a failed change was rolled back, or when the card's state is
    uncertain. The message is i20's one-line reason, and C(cells) names every cell that may
    differ.
version_added: "0.1.0"
author: i20tools
options:
  profile:
    description:
      - A profile file (YAML) on the managed host, or the name of a shipped profile
        (C(line-240v)). i20 looks it up in C($I20_PROFILE_PATH), then in the installed
        C(share/i20tools/profiles).
    type: str
    required: true
  port:
    description:
      - Where the 8I20 is. Give a serial device (C(/dev/ttyUSB0)), C(COMn), or an SSERIAL
        channel C(eth://IP[:UDPPORT][/portP][/chN]) of a 7I96S/7I92T.
      - Exactly one of I(port) and I(sim_eeprom) is required.
    type: str
  sim_eeprom:
    description:
      - Use i20's built-in simulator card with its EEPROM stored in this file
        (C(i20 --sim --sim-eeprom FILE)). This is for tests and rehearsals.
    type: path
  sim_control:
    description:
      - Control lines for the simulator card applied before the first command (C(busv 160)
        stands in for a card on a 120 V line). Only with I(sim_eeprom).
    type: list
    elements: str
    default: []
  reset:
    description:
      - Reset the 8I20 after a verified apply, or when an earlier EEPROM write is not live yet,
        so the new EEPROM values take effect at once (C(--reset --yes)).
    type: bool
    default: false
  backup_dir:
    description:
      - Where i20 writes the backup of the card's values before the first write. The default
        is i20's own, C($XDG_STATE_HOME/i20/backups) of the user the task runs as.
    type: path
  force:
    description:
      - Allow guarded parameters (NVBAUDRATE), and BUSOVERV/BRAKEONV at or below the measured
        bus (C(--force)).
    type: bool
    default: false
  allow_unverified:
    description:
      - Write working (RAM) addresses the parameter database does not confirm for the card's
        firmware (C(--allow-unverified)).
    type: bool
    default: false
  to:
    description:
      - Aim every entry of the profile at the EEPROM (C(nv)), the working values (C(working))
        or both (C(--to)). The default is the profile's own targets.
    type: str
    choices: [nv, working, both]
  i20:
    description:
      - The i20 program. The default is C(i20) found on the managed host's PATH.
    type: str
    default: i20
notes:
  - Supports check mode and diff mode.
  - The 8I20 must be in setup mode for the serial port (jumper W6 down). Over Ethernet, i20
    refuses to disturb a port that another host (LinuxCNC) is driving.
requirements:
  - The i20 program of i20tools on the managed host.
"""

EXAMPLES = r"""
- name: The 120 V line profile on the X axis
  i20_profile:
    profile: line-120v
    port: /dev/ttyUSB0
    backup_dir: /var/lib/i20/backups

- name: A shop profile on an 8I20 behind a 7I96S, made live at once
  i20_profile:
    profile: /etc/i20/spindle.yaml
    port: eth://192.168.1.121/port0/ch1
    reset: true

- name: Rehearse against a simulator card
  i20_profile:
    profile: line-240v
    sim_eeprom: /tmp/axis-x.eeprom
  check_mode: true
  diff: true
"""

RETURN = r"""
outcome:
  description:
    - i20's outcome. One of C(done), C(nothing-to-do), C(dry-run), C(failed),
      C(bad-input), C(invalid) (the profile cannot be read), C(refused), C(rolled-back),
      C(uncertain), C(interrupted).
  returned: always
  type: str
  sample: done
exit_code:
  description: i20's exit code (0 ok, 1 not reached, 2 bad input, 3 refused, 4 rolled back or uncertain, 130 interrupted).
  returned: always
  type: int
  sample: 0
summary:
  description: i20's closing line.
  returned: when i20 reached the card
  type: str
  sample: "APPLIED AND VERIFIED: 5 values written"
written:
  description: The cells written and read back, in the order written.
  returned: always
  type: list
  elements: dict
  sample: [{"cell": "NVBRAKEONV", "raw": 19000, "text": "190 V"}]
planned:
  description: The cells that differ from the profile, with the card's value before and the profile's after.
  returned: when i20 reached the card
  type: list
  elements: dict
  sample: [{"cell": "NVBRAKEONV", "before": "360 V", "after": "190 V", "nv": true}]
backup:
  description: The backup file of the card's previous values, or null when nothing was backed up.
  returned: always
  type: str
  sample: /var/lib/i20/backups/8I20-0x12345678-20260101T120000Z.yaml
card:
  description: The card as i20 describes it (name, unit number, firmware, where).
  returned: when i20 reached the card
  type: str
reset_needed:
  description: EEPROM values are written but not live until the card is reset.
  returned: when i20 reached the card
  type: bool
reset_done:
  description: i20 reset the card (I(reset)).
  returned: when i20 reached the card
  type: bool
cells:
  description:
    - The state of every cell the run touched, after a failure. C(status) says whether it holds
      the old, the new or an unknown value.
  returned: when i20 reached the card
  type: list
  elements: dict
cmd:
  description: The i20 command line that was run.
  returned: always
  type: list
  elements: str
"""

import json

from ansible.module_utils.basic import AnsibleModule


def target_args(params):
    if params["port"]:
        return ["--port", params["port"]]
    args = ["--sim", "--sim-eeprom", params["sim_eeprom"]]
    for line in params["sim_control"]:
        args += ["--sim-control", line]
    return args


def build_command(module, program):
    p = module.params
    cmd = [program, "--json"] + target_args(p) + ["profile", "apply", p["profile"]]
    if p["backup_dir"]:
        cmd += ["--backup-dir", p["backup_dir"]]
    if p["to"]:
        cmd += ["--to", p["to"]]
    for flag in ("force", "allow_unverified"):
        if p[flag]:
            cmd.append("--" + flag.replace("_", "-"))
    if p["reset"]:
        cmd += ["--reset", "--yes"]
    if module.check_mode:
        cmd.append("--dry-run")
    return cmd


def find_program(module, name):
    if "/" in name:
        return name
    return module.get_bin_path(name, required=True)


def parse_json(stdout):
    try:
        data = json.loads(stdout)
    except ValueError:
        return {}
    return data if isinstance(data, dict) else {}


def finding_text(f):
    text = f.get("message", "")
    return text + (" [%s]" % f["rule"] if f.get("rule") else "")


def one_line(data, stderr, rc):
    # i20's own one-line reason (what it prints on stderr without --json): a refusal names
    # the rules that refused, an invalid profile what is wrong with it.
    if data.get("type") == "error" and data.get("error"):
        return data["error"]  # a failure i20 reported as JSON (before or outside the apply)
    errors = [finding_text(f) for f in data.get("findings") or [] if f.get("severity") == "error"]
    if data.get("outcome") == "invalid" and errors:
        return "%s: %s" % (data.get("file"), "; ".join(errors))
    if data.get("outcome") in ("refused", "bad-input"):
        return "refused: " + ("; ".join(errors) if errors else data.get("reason") or data.get("summary", ""))
    if data.get("summary"):
        return data["summary"]
    for line in reversed(stderr.splitlines()):
        if line.strip():
            return line.strip()
    return "i20 exited with code %d" % rc


def planned_of(data):
    steps = (data.get("plan") or {}).get("steps") or []
    return [
        {"cell": s["cell"], "before": s.get("card_text"), "after": s.get("profile_text"), "nv": s.get("nv")}
        for s in steps
    ]


def written_of(data):
    return [
        {"cell": w["cell"], "raw": w.get("raw"), "text": w.get("text")}
        for w in data.get("writes") or []
        if w.get("ok") and not w.get("skipped")
    ]


def diff_of(planned, card):
    lines = lambda key: "".join("%s: %s\n" % (p["cell"], p[key]) for p in planned)
    return {
        "before": lines("before"),
        "after": lines("after"),
        "before_header": "%s (card)" % card,
        "after_header": "%s (profile)" % card,
    }


def main():
    module = AnsibleModule(
        argument_spec=dict(
            profile=dict(type="str", required=True),
            port=dict(type="str"),
            sim_eeprom=dict(type="path"),
            sim_control=dict(type="list", elements="str", default=[]),
            reset=dict(type="bool", default=False),
            backup_dir=dict(type="path"),
            force=dict(type="bool", default=False),
            allow_unverified=dict(type="bool", default=False),
            to=dict(type="str", choices=["nv", "working", "both"]),
            i20=dict(type="str", default="i20"),
        ),
        mutually_exclusive=[("port", "sim_eeprom"), ("port", "sim_control")],
        required_one_of=[("port", "sim_eeprom")],
        supports_check_mode=True,
    )
    cmd = build_command(module, find_program(module, module.params["i20"]))
    rc, stdout, stderr = module.run_command(cmd)
    data = parse_json(stdout)
    planned = planned_of(data)
    result = dict(
        cmd=cmd,
        exit_code=rc,
        outcome=data.get("outcome", "failed" if rc else "done"),
        summary=data.get("summary"),
        written=written_of(data),
        planned=planned,
        backup=data.get("backup"),
        card=data.get("card"),
        reset_needed=data.get("reset_needed"),
        reset_done=data.get("reset_done"),
        cells=data.get("cells") or [],
        not_live=data.get("not_live") or [],
    )
    if data.get("findings"):
        result["findings"] = data["findings"]
    if rc != 0:
        module.fail_json(msg=one_line(data, stderr, rc), stderr=stderr, **result)
    if module.check_mode:
        result["changed"] = bool(planned)
    else:
        result["changed"] = bool(result["written"]) or bool(data.get("reset_done"))
    if module._diff and planned:
        result["diff"] = diff_of(planned, data.get("card") or data.get("target", ""))
    module.exit_json(**result)


if __name__ == "__main__":
    main()
