# SPDX-License-Identifier: GPL-2.0-or-later
# An Ansible module over `i20 --json report`: the field-service report of one 8I20 as facts.
# Read-only; every value is what i20 read from the card (or null with the reason).

DOCUMENTATION = r"""
---
module: i20_facts
short_description: Read one Mesa 8I20 servo amplifier's field-service report as facts
description:
  - Runs C(i20 --json report) on the managed host against one 8I20 and returns the report as
    C(ansible_facts). The report holds the card's identity (name, unit number, firmware
    SWREVISION), whether the working map is confirmed for that firmware, every parameter, the
    EEPROM values that are not live yet, and FAULT and STATUS with their bits decoded.
  - Read-only. Nothing is written to the card, and the task never reports a change.
  - A parameter i20 could not read as a fact has C(fact=false) and C(raw=null). Its C(text)
    says why.
version_added: "0.1.0"
author: i20tools
options:
  port:
    description:
      - Where the 8I20 is. Give a serial device (C(/dev/ttyUSB0)), C(COMn), or an SSERIAL
        channel C(eth://IP[:UDPPORT][/portP][/chN]) of a 7I96S/7I92T.
      - Exactly one of I(port) and I(sim_eeprom) is required.
    type: str
  sim_eeprom:
    description:
      - Use i20's built-in simulator card with its EEPROM stored in this file (for tests).
    type: path
  sim_control:
    description:
      - Control lines for the simulator card (C(busv 160)). Only with I(sim_eeprom).
    type: list
    elements: str
    default: []
  fact_name:
    description:
      - The name of the fact the report is stored under. Use one name per axis when a host has
        several 8I20s.
    type: str
    default: i20
  i20:
    description:
      - The i20 program. The default is C(i20) found on the managed host's PATH.
    type: str
    default: i20
notes:
  - Supports check mode (it only reads).
requirements:
  - The i20 program of i20tools on the managed host.
"""

EXAMPLES = r"""
- name: Read the X axis amplifier
  i20_facts:
    port: /dev/ttyUSB0
    fact_name: i20_x

- name: Stop when it has a fault latched
  ansible.builtin.assert:
    that: ansible_facts.i20_x.faults.fault == 0
    fail_msg: "{{ ansible_facts.i20_x.faults.fault_bits | join(', ') }}"

- name: Its brake-on voltage
  ansible.builtin.debug:
    msg: "{{ ansible_facts.i20_x.parameters.NVBRAKEONV.text }}"
"""

RETURN = r"""
ansible_facts:
  description: The report, under I(fact_name).
  returned: always
  type: complex
  contains:
    i20:
      description: The report of the card (the key is I(fact_name)).
      returned: always
      type: complex
      contains:
        target:
          description: The target as given.
          type: str
        tool:
          description: The i20tools version that read the card.
          type: str
        time:
          description: When the card was read (ISO 8601, UTC).
          type: str
        card:
          description:
            - The card's name, C(unit_number), C(swrevision), C(working_map_confirmed) (whether
              the database confirms the working addresses for this firmware), C(lbp_status),
              C(crc_errors) and what the RPC table confirmed (C(rpc_table)).
          type: dict
        faults:
          description:
            - C(fault), C(status) (integers and C(fault_hex)/C(status_hex)), and
              C(fault_bits)/C(status_bits), the names of the bits that are set. Null when
              they could not be read; C(faults_unknown_because) says why.
          type: dict
        parameters:
          description:
            - Every parameter by name, each with C(raw) (the card's integer, null if unknown),
              C(text) (engineering units, or why it is unknown), C(fact) and C(space)
              (C(nv) or C(working)).
          type: dict
          sample: {"NVBRAKEONV": {"raw": 36000, "text": "360 V", "fact": true, "space": "nv"}}
        nv_not_live_yet:
          description: EEPROM cells whose working twin holds another value until the next reset.
          type: list
          elements: str
        link:
          description: The link's statistics (exchanges, commands, timeouts, CRC errors, resyncs, retries).
          type: dict
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


def find_program(module, name):
    if "/" in name:
        return name
    return module.get_bin_path(name, required=True)


def as_facts(report):
    facts = {k: v for k, v in report.items() if k != "values"}
    facts["parameters"] = {
        v["name"]: {"raw": v.get("raw"), "text": v.get("text"), "fact": v.get("fact"), "space": v.get("space")}
        for v in report.get("values") or []
    }
    return facts


def last_line(text):
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1] if lines else ""


def main():
    module = AnsibleModule(
        argument_spec=dict(
            port=dict(type="str"),
            sim_eeprom=dict(type="path"),
            sim_control=dict(type="list", elements="str", default=[]),
            fact_name=dict(type="str", default="i20"),
            i20=dict(type="str", default="i20"),
        ),
        mutually_exclusive=[("port", "sim_eeprom"), ("port", "sim_control")],
        required_one_of=[("port", "sim_eeprom")],
        supports_check_mode=True,
    )
    cmd = [find_program(module, module.params["i20"]), "--json"] + target_args(module.params) + ["report"]
    rc, stdout, stderr = module.run_command(cmd)
    if rc != 0:
        module.fail_json(msg=last_line(stderr) or "i20 exited with code %d" % rc, exit_code=rc, cmd=cmd)
    try:
        report = json.loads(stdout)
    except ValueError:
        module.fail_json(msg="i20 report printed no JSON document", exit_code=rc, cmd=cmd, stdout=stdout)
    module.exit_json(changed=False, cmd=cmd, ansible_facts={module.params["fact_name"]: as_facts(report)})


if __name__ == "__main__":
    main()
