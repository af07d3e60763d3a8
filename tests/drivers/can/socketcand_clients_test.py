#!/usr/bin/python3
"""Two python-can (Debian python3-can) socketcand clients through `crease-simdevice socketcand`.

One client sends 10,000 frames (standard and extended ids, 0..8 bytes); the other client of
the same bridge must receive every one, in order, ids and data unchanged, and so must a node
on the mocked bus (`crease-simdevice record`, whose candump -L log python-can's
CanutilsLogReader reads back, with wall-clock timestamps).
usage: socketcand_clients_test.py CREASE_SIMDEVICE
"""
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

import logging

import can

# python-can 4.1 warns for every message split across two reads ("incomplete message").
logging.getLogger("can.interfaces.socketcand").setLevel(logging.ERROR)

N = int(os.environ.get("CREASE_SCD_FRAMES", "10000"))
PROBE = 0x7FF


def expected(i):
    # python-can 4.1 sends an id above 0x7FF as extended, others as standard (no flag).
    if i % 3 == 2:
        ident, ext = 0x800 + (i * 7919) % (0x1FFFFFFF - 0x800), True
    else:
        ident, ext = i % 0x7FF, False
    length = i % 9
    data = bytes(((i >> (8 * (k % 2))) + k) & 0xFF for k in range(length))
    return ident, ext, data


def start(args, ready_prefix):
    """Starts a crease-simdevice process; returns it and its first line starting with ready_prefix."""
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    if not line.startswith(ready_prefix):
        p.kill()
        sys.exit(f"FAIL: {' '.join(args)} printed {line!r}, stderr: {p.stderr.read()}")
    return p, line.strip()


def stop(p):
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=30)
    return p.returncode, err


def main():
    exe = sys.argv[1]
    bus = f"scdpy-{os.getpid()}"
    tmp = tempfile.mkdtemp(prefix="crease_scdpy_")
    log = os.path.join(tmp, "bus.log")
    procs = []
    try:
        broker, _ = start([exe, "broker", "--bus", bus], "broker:")
        procs.append(broker)
        recorder = subprocess.Popen([exe, "record", "--bus", bus, "--out", log], stderr=subprocess.PIPE, text=True)
        procs.append(recorder)
        bridge, line = start([exe, "socketcand", "--bus", bus, "--listen", "127.0.0.1:0"], "socketcand:")
        procs.append(bridge)
        port = int(line.rsplit(":", 1)[1])
        rx = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
        tx = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)

        # Probes until the receiver sees one: both clients are then in rawmode and forwarded to.
        synced = threading.Event()

        def send_all():
            while not synced.is_set():
                tx.send(can.Message(arbitration_id=PROBE, data=b"probe", is_extended_id=False))
                synced.wait(0.05)
            for i in range(N):
                ident, ext, data = expected(i)
                tx.send(can.Message(arbitration_id=ident, data=data, is_extended_id=ext))

        sender = threading.Thread(target=send_all)
        sender.start()
        got = []
        bad = []
        while len(got) < N:
            m = rx.recv(30)  # silence for this long: the bridge lost frames (not a speed limit)
            if m is None:
                break
            if m.arbitration_id == PROBE and bytes(m.data) == b"probe":
                synced.set()
                if not got:
                    continue
            i = len(got)
            ident, ext, data = expected(i)
            # python-can 4.1's socketcand client marks every received frame extended: compare the
            # id and data here, the id's format on the bus below.
            if (m.arbitration_id, bytes(m.data)) != (ident, data):
                bad.append((i, hex(m.arbitration_id), bytes(m.data).hex(), hex(ident), data.hex()))
            got.append(m)
        synced.set()
        sender.join()
        print(f"client received {len(got)} of {N} frames from the other client, {len(bad)} differ")
        if len(got) != N or bad:
            sys.exit(f"FAIL: first differences (index, id, data, expected id, data): {bad[:5]}")

        # The bus saw the same frames in the same order.
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            time.sleep(0.2)
            if os.path.exists(log) and sum(1 for _ in open(log)) >= N:
                break
        rc, err = stop(recorder)
        procs.remove(recorder)
        frames = [m for m in can.CanutilsLogReader(log) if not (m.arbitration_id == PROBE and bytes(m.data) == b"probe")]
        print(f"bus node recorded {len(frames)} frames; {err.strip()}")
        if len(frames) != N:
            sys.exit(f"FAIL: the bus node recorded {len(frames)} frames, not {N}")
        for i, m in enumerate(frames):
            if (m.arbitration_id, m.is_extended_id, bytes(m.data)) != expected(i):
                sys.exit(f"FAIL: bus frame {i}: {m}")
        # candump -L stamps are wall-clock epoch seconds (2020 or later), not uptime.
        if frames[0].timestamp < 1.58e9:
            sys.exit(f"FAIL: log timestamp {frames[0].timestamp} is not epoch time")
        rx.shutdown()
        tx.shutdown()
        print("ok")
    finally:
        for p in procs:
            p.kill()
            p.wait()


if __name__ == "__main__":
    main()
