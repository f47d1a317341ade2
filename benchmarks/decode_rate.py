"""Reading cost of a recording: per-message decoding, ``read_recording``, ``inspect_recording``.

``python benchmarks/decode_rate.py FILE.mcap [--base OTHER_CHECKOUT]`` prints, for each message
type of the file, the decoding cost per message of mcap-ros2-support's decoder and of the
generated one (:mod:`twodisk_ros.recordings.cdr_decode`), best of 3 passes over all its messages with
the garbage collector off (decoding alone); then the wall time of ``inspect_recording`` and
``read_recording`` (best of 3, each in a fresh process), and with ``--base`` the same for
another checkout of the package (e.g. one before a change), the runs interleaved so that both
see the same machine load.  Not part of ``make bench``.
"""

import argparse
import gc
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_TIMED = '''
import sys, time
from twodisk_ros.inspector.inspection import inspect_recording
from twodisk_ros.recordings import read_recording
what, path = sys.argv[1], sys.argv[2]
start = time.perf_counter()
(inspect_recording if what == 'inspect' else read_recording)(path)
print(time.perf_counter() - start)
'''


def per_message(path):
    """``{type: (messages, mcap_ros2 s per message, generated s per message)}``."""
    sys.path.insert(0, ROOT)
    from mcap_ros2.decoder import DecoderFactory as McapDecoderFactory
    from twodisk_ros.recordings.cdr_decode import compile_decoder
    from twodisk_ros.recordings.mcap_scan import scan_mcap
    with open(path, 'rb') as stream:
        scan = scan_mcap(stream.read())
    channels = {**scan.summary_channels, **scan.channels}
    schemas = {**scan.summary_schemas, **scan.schemas}
    payloads = {}
    for raw in scan.messages:
        payloads.setdefault(channels[raw.channel_id].schema_id, []).append(raw.data)
    costs = {}
    gc.disable()
    try:
        for sid, datas in payloads.items():
            schema = schemas[sid]
            fast, _ = compile_decoder(schema.name, schema.data.decode())
            theirs = McapDecoderFactory().decoder_for('cdr', schema)
            best = []
            for decode in (theirs, fast):
                times = []
                for _ in range(3):
                    start = time.perf_counter()
                    for data in datas:
                        decode(data)
                    times.append((time.perf_counter() - start) / len(datas))
                best.append(min(times))
            costs[schema.name] = (len(datas), *best)
    finally:
        gc.enable()
    return costs


def wall_times(path, checkouts, what, repeats=3):
    """Best wall time of ``what`` ('inspect' or 'read') per checkout, runs interleaved."""
    times = {name: [] for name in checkouts}
    for _ in range(repeats):
        for name, root in checkouts.items():
            env = dict(os.environ, PYTHONPATH=root, MPLBACKEND='Agg')
            out = subprocess.run([sys.executable, '-c', _TIMED, what, path], env=env, cwd=root,
                                 capture_output=True, text=True, check=True)
            times[name].append(float(out.stdout.split()[-1]))
    return {name: min(values) for name, values in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('path')
    parser.add_argument('--base', help='another checkout of the package to compare with')
    args = parser.parse_args()
    costs = per_message(args.path)
    total = [0.0, 0.0]
    print(f'{"type":40s} {"messages":>8s} {"mcap_ros2 us":>12s} {"generated us":>12s} {"x":>5s}')
    for name, (count, theirs, ours) in costs.items():
        total[0] += count * theirs
        total[1] += count * ours
        print(f'{name:40s} {count:8d} {theirs * 1e6:12.1f} {ours * 1e6:12.1f} '
              f'{theirs / ours:5.1f}')
    print(f'all messages: mcap_ros2 {total[0]:.2f} s, generated {total[1]:.2f} s')
    checkouts = {'this checkout': ROOT}
    if args.base:
        checkouts['base'] = os.path.abspath(args.base)
    for what in ('inspect', 'read'):
        best = wall_times(args.path, checkouts, what)
        print(f'{what}_recording, best of 3: ' + ', '.join(
            f'{name} {seconds:.2f} s' for name, seconds in best.items()))


if __name__ == '__main__':
    main()
