"""``twodisk-view`` in real time: what a Foxglove client receives, and what it costs the server.

The command runs as a process (as users run it: ``python -m twodisk_ros.view`` with
``config/oloid.yaml``, ``--rate`` 100 Hz or 1 kHz, a free port); a raw ``websockets`` client
in this process (subprotocol ``foxglove.sdk.v1``) subscribes to every channel and, over
``seconds`` of wall time, counts the messages of each channel without decoding them (a
decoding client would measure itself) and the lag of arrival behind each ``/tf`` stamp (in
a live run stamps follow the wall clock). The server's CPU time over the same window comes
from /proc; the samples it skipped to keep up, from its last line.

Run ``python benchmarks/view_rate.py [--quick]`` (PYTHONPATH = the repository); prints JSON.
"""

import argparse
import asyncio
from dataclasses import asdict, dataclass
import json
import os
import re
import signal
import struct
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUBPROTOCOL = 'foxglove.sdk.v1'


@dataclass
class ViewRate:
    rate_hz: float          #: --rate of the run
    seconds: float          #: wall time measured (s)
    transforms: int         #: /tf messages received (one per sample)
    scenes: dict            #: SceneUpdate / JSON messages received, by channel
    lag_p50_ms: float       #: arrival time minus stamp of /tf, median (ms)
    lag_p99_ms: float       #: ... 99th percentile (ms)
    server_cpu: float       #: server CPU time / wall time over the window (1 = one core)
    skipped: int            #: samples the server skipped to keep up (whole run)

    @property
    def per_second(self):
        return self.transforms / self.seconds

    def as_dict(self):
        return dict(asdict(self), per_second=self.per_second)


def _cpu_seconds(pid):
    with open(f'/proc/{pid}/stat', encoding='ascii') as stream:
        fields = stream.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


async def _client(port, seconds, pid):
    from websockets.asyncio.client import connect
    counts, topics, lags = {}, {}, []
    async with connect(f'ws://127.0.0.1:{port}', subprotocols=[SUBPROTOCOL],
                       max_size=None) as socket:
        start, cpu0 = time.monotonic(), _cpu_seconds(pid)
        while time.monotonic() - start < seconds:
            try:
                frame = await asyncio.wait_for(socket.recv(), 1.0)
            except TimeoutError:
                continue
            if isinstance(frame, str):
                op = json.loads(frame)
                if op['op'] == 'advertise':
                    topics.update({c['id']: c['topic'] for c in op['channels']})
                    await socket.send(json.dumps({'op': 'subscribe', 'subscriptions': [
                        {'id': c['id'], 'channelId': c['id']} for c in op['channels']]}))
            elif frame[0] == 0x01:
                subscription, log_time = struct.unpack_from('<IQ', frame, 1)
                topic = topics[subscription]
                counts[topic] = counts.get(topic, 0) + 1
                if topic == '/tf':
                    lags.append((time.time_ns() - log_time) * 1e-6)
        wall, cpu = time.monotonic() - start, _cpu_seconds(pid) - cpu0
    return counts, sorted(lags), wall, cpu


def view_rate(rate_hz, seconds=10.0):
    """Run ``twodisk-view`` at ``rate_hz`` for ``seconds`` with one client: a ViewRate."""
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get('PYTHONPATH', ''))
    process = subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.view', '--params-file',
         os.path.join(ROOT, 'config', 'oloid.yaml'), '--rate', f'{rate_hz:g}', '--port', '0'],
        cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = process.stdout.readline()
        match = re.search(r'ws://127\.0\.0\.1:(\d+)', line)
        if match is None:
            raise RuntimeError(f'twodisk-view did not start: {line!r}')
        counts, lags, wall, cpu = asyncio.run(_client(int(match.group(1)), seconds,
                                                      process.pid))
        os.kill(process.pid, signal.SIGINT)
        rest = process.communicate(timeout=60)[0]
    finally:
        if process.poll() is None:
            os.kill(process.pid, signal.SIGKILL)
            process.wait()
    skipped = re.search(r'(\d+) skipped', rest)

    def percentile(q):
        return lags[min(len(lags) - 1, int(q * len(lags)))] if lags else float('nan')
    return ViewRate(rate_hz, wall, counts.get('/tf', 0),
                    {k: v for k, v in counts.items() if k != '/tf'}, percentile(0.5),
                    percentile(0.99), cpu / wall, int(skipped.group(1)) if skipped else 0)


def report_lines(results):
    """The report's section for these measurements (Markdown lines)."""
    lines = ['## Live view without ROS (twodisk-view)\n',
             '`python -m twodisk_ros.view --params-file config/oloid.yaml --rate R` as a '
             'process; one raw WebSocket client (subprotocol foxglove.sdk.v1) subscribed to '
             'every channel, counting messages without decoding them. Lag: arrival time minus '
             'the stamp of each /tf message. Server CPU: its CPU time over the window (1 = one '
             'core of this 2-core machine, which the client shares).\n',
             '| rate (Hz) | seconds | /tf received (per s) | contact segments | force arrows | '
             'traces | lag p50 (ms) | lag p99 (ms) | server CPU | skipped |',
             '|---|---|---|---|---|---|---|---|---|---|']
    for r in results:
        s = r.scenes
        lines.append(f'| {r.rate_hz:g} | {r.seconds:.1f} | {r.transforms} ({r.per_second:.0f}) '
                     f'| {s.get("/contact_segment", 0)} | {s.get("/contact_forces", 0)} | '
                     f'{s.get("/traces", 0)} | {r.lag_p50_ms:.2f} | {r.lag_p99_ms:.2f} | '
                     f'{r.server_cpu:.0%} | {r.skipped} |')
    lines.append('')
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quick', action='store_true', help='3 s per rate instead of 10 s')
    args = parser.parse_args(argv)
    results = [view_rate(hz, 3.0 if args.quick else 10.0) for hz in (100.0, 1000.0)]
    print(json.dumps([r.as_dict() for r in results], indent=1))


if __name__ == '__main__':
    main()
