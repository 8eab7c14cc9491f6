#!/usr/bin/env python3
"""Writes the seed inputs of the binary fuzz targets (modbus_map, wire_spans, can_node,
cia402_drive) in the layout each target's harness reads. Run from fuzz/corpus/."""
import struct


def span(ticks, end, flags=0, axes=2):
    """A wire span: big-endian ticks-1, flags, outputs, then per axis end, T1, T0."""
    out = struct.pack(">HBB", ticks - 1, flags, 0)
    for a in range(axes):
        out += struct.pack(">iii", end[a], 0, 0)
    return out


def registers(b):
    if len(b) % 2:
        b += b"\0"
    return [struct.unpack(">H", b[i:i + 2])[0] for i in range(0, len(b), 2)]


def write(path, data):
    with open(path, "wb") as f:
        f.write(bytes(data))


payload = span(8, (10, 0)) + span(8, (20, 0)) + span(8, (30, 0), flags=2)

# wire_spans: axes byte, then batches (first, count, length, payload, ticks).
write("wire_spans/three_spans", bytes([1]) + bytes([1, 3, len(payload)]) + payload + bytes([40]))
write("wire_spans/resend", bytes([1]) + (bytes([1, 3, len(payload)]) + payload + bytes([0])) * 2)

# modbus_map: configure flag, then (op, address byte, ...) requests.
config = [0, 1000, 2] + [0] * 7 + [0x000F, 0x4240, 0x05F5, 0xE100] * 2 + [0] * 8
config_write = bytes([2, 2, len(config) - 1]) + b"".join(struct.pack(">H", v) for v in config)
header = [0, 1, 3, 0, 0]  # first 1, 3 spans; length and check filled by the harness
regs = header + registers(payload)
batch = bytes([3, 3, len(regs) - 1]) + b"".join(struct.pack(">H", v) for v in regs)
start = bytes([2, 1, 0, 0, 1])  # FC16 one register at the command register: start
write("modbus_map/configure_batch_start", bytes([0]) + config_write + batch + start + bytes([4, 0, 200]))
write("modbus_map/preconfigured", bytes([1]) + batch + batch + bytes([0, 0, 49, 1, 128, 10]))

# can_node: configure flag, then frames (how, length, 8 data bytes).
def frame(function_index, data, length=None):
    return bytes([function_index, len(data) if length is None else length]) + (bytes(data) + bytes(8))[:8]

start_frame = frame(3, struct.pack("<IBHB", 1, 3, len(payload), 0))
data_frames = b"".join(frame(4, bytes([i]) + payload[7 * i:7 * i + 7]) for i in range((len(payload) + 6) // 7))
write("can_node/batch", bytes([1]) + start_frame + data_frames + frame(0, [1]))
write("can_node/oversized", bytes([1]) + start_frame + bytes([4 | 16, 200]) + bytes(8))

# cia402_drive: (how, length, 8 data bytes, time step) per frame.
def co(how, data, step=1):
    return bytes([how, len(data)]) + (bytes(data) + bytes(8))[:8] + bytes([step])

nmt_start = co(0, [0x01, 3])
sdo_mode = co(2, [0x2F, 0x60, 0x60, 0, 8, 0, 0, 0])       # 0x6060 = 8 (CSP)
sdo_period = co(2, [0x2F, 0xC2, 0x60, 1, 2, 0, 0, 0])     # 0x60C2.1 = 2
control = [co(3, [v, 0, 0, 0, 0, 0]) for v in (0x06, 0x07, 0x0F)]
write("cia402_drive/enable_csp", nmt_start + sdo_mode + sdo_period + b"".join(control) + co(1, [], 20) * 3)
write("cia402_drive/sdo_upload", co(2, [0x40, 0x41, 0x60, 0, 0, 0, 0, 0]) + co(2, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0]))
