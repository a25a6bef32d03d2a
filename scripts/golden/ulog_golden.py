"""Golden values for the ulog crate's reader, computed with pyulog (the reference implementation of
the ULog format) on the two public logs in ../shared/data/ulog (see its README).

Usage: scripts/python-env.sh ulog && .venv-ulog/bin/python scripts/golden/ulog_golden.py \
           > scripts/golden/ulog_golden.json
"""

import importlib.metadata
import json
import math
import os


from pyulog import ULog

DATA = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "ulog")
FILES = ["sample_px4_events.ulg", "quadrotor_local.ulg"]

# Topics a flight analysis reads, with a few of their fields whose values are checked.
TOPICS = {
    "vehicle_local_position": ["x", "vz", "heading"],
    "vehicle_attitude": ["q[0]", "q[3]"],
    "vehicle_angular_velocity": ["xyz[0]", "xyz[2]"],
    "actuator_motors": ["control[0]", "control[3]"],
    "actuator_outputs": ["output[0]", "output[3]"],
    "battery_status": ["voltage_v", "current_a"],
    "vehicle_thrust_setpoint": ["xyz[2]"],
    "vehicle_torque_setpoint": ["xyz[0]", "xyz[2]"],
}
PARAMETERS = ["MPC_XY_VEL_MAX", "MPC_Z_VEL_MAX_UP", "MPC_THR_HOVER", "MPC_TILTMAX_AIR",
              "CA_ROTOR_COUNT", "CA_ROTOR0_PX", "SYS_AUTOSTART"]


def number(value):
    value = value.item() if hasattr(value, "item") else value
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def topic(ulog, name):
    data = ulog.get_dataset(name, 0)
    n = len(data.data["timestamp"])
    samples = sorted({0, 1, n // 2, n - 1})
    return {
        "name": name,
        "samples": n,
        "first_timestamp": int(data.data["timestamp"][0]),
        "last_timestamp": int(data.data["timestamp"][-1]),
        # Columns without padding (the crate leaves every _padding field out).
        "fields": [f.field_name for f in data.field_data if not f.field_name.startswith("_padding")],
        "values": {
            field: {str(k): number(data.data[field][k]) for k in samples} for field in TOPICS[name]
        },
    }


def golden(file):
    ulog = ULog(os.path.join(DATA, file))
    return {
        "file": file,
        "start_timestamp": ulog.start_timestamp,
        "last_timestamp": ulog.last_timestamp,
        "info": {key: ulog.msg_info_dict[key] for key in ["sys_name", "ver_hw", "ver_sw"]
                 if key in ulog.msg_info_dict},
        "info_keys": sorted(ulog.msg_info_dict.keys()),
        "multi_info_keys": sorted(ulog.msg_info_multiple_dict.keys()),
        "parameters": {name: ulog.initial_parameters.get(name) for name in PARAMETERS},
        "parameter_count": len(ulog.initial_parameters),
        "changed_parameters": [[int(t), name, number(v)] for t, name, v in ulog.changed_parameters],
        "system_default_count": len(ulog.get_default_parameters(0)),
        "configuration_default_count": len(ulog.get_default_parameters(1)),
        "dropouts": [[int(d.timestamp), int(d.duration)] for d in ulog.dropouts],
        "logged_messages": len(ulog.logged_messages),
        "tagged_logged_messages": sum(len(v) for v in ulog.logged_messages_tagged.values()),
        "first_logged_message": (
            [int(ulog.logged_messages[0].timestamp), ulog.logged_messages[0].message]
            if ulog.logged_messages else None),
        # Every topic instance with data: name, instance, sample count.
        "topics": [[d.name, d.multi_id, len(d.data["timestamp"])] for d in ulog.data_list],
        "checked_topics": [topic(ulog, name) for name in TOPICS],
    }


def main():
    print(json.dumps({
        "generator": "scripts/golden/ulog_golden.py",
        "pyulog": importlib.metadata.version("pyulog"),
        "logs": [golden(file) for file in FILES],
    }, indent=1))


if __name__ == "__main__":
    main()
