"""A minimal Foxglove WebSocket client for the tests of ``twodisk-view`` (``websockets``).

It speaks the subprotocol the server offers, reads the server info and the channel
advertisements, subscribes to every channel and decodes the messages by their advertised
schema: protobuf through a descriptor pool built from the advertised FileDescriptorSet
(``google.protobuf``), JSON with ``json``. Nothing of twodisk_ros or foxglove-sdk is used, so
the messages are read as Foxglove would read them.
"""

import asyncio
import base64
from dataclasses import dataclass, field
import json
import struct
import time

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
import websockets
from websockets.asyncio.client import connect

SUBPROTOCOL = 'foxglove.sdk.v1'
MESSAGE_DATA, TIME = 0x01, 0x02
#: s to wait for the server's answer to the client's close frame (websockets' default: 10)
CLOSE_TIMEOUT = 0.2


@dataclass
class Received:
    """What a client saw: server info, channels by topic, messages by topic, server times."""

    server_info: dict = None
    channels: dict = field(default_factory=dict)       # topic -> advertised channel (dict)
    messages: dict = field(default_factory=dict)       # topic -> [(log_time_ns, message)]
    times: list = field(default_factory=list)          # ns
    parameters: list = field(default_factory=list)     # parameterValues ops

    def count(self, topic):
        return len(self.messages.get(topic, ()))


def _decoder(channel):
    """A function bytes -> message for an advertised channel."""
    if channel['encoding'] == 'json':
        return lambda data: json.loads(data.decode('utf-8'))
    if channel['encoding'] != 'protobuf' or channel['schemaEncoding'] != 'protobuf':
        raise AssertionError(f'unexpected encoding of {channel["topic"]}: {channel}')
    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel['schema']))
    pool = descriptor_pool.DescriptorPool()
    pending = list(files.file)
    while pending:                          # add each file after its dependencies
        added = [f for f in pending if all(_known(pool, d) for d in f.dependency)]
        if not added:
            raise AssertionError(f'unresolved imports in the schema of {channel["topic"]}')
        for proto in added:
            pool.Add(proto)
            pending.remove(proto)
    kind = message_factory.GetMessageClass(pool.FindMessageTypeByName(channel['schemaName']))
    return kind.FromString


def _known(pool, name):
    try:
        pool.FindFileByName(name)
        return True
    except KeyError:
        return False


async def _collect(port, topics, enough, timeout, request_parameters):
    received = Received()
    url = f'ws://127.0.0.1:{port}'
    deadline = time.monotonic() + timeout
    # close_timeout: the client has what it came for when it closes; a view that is idle
    # (its run ended, nothing sent) answers the closing handshake only after websockets'
    # default 10 s, which the tests would otherwise sit through
    async with connect(url, subprotocols=[SUBPROTOCOL], max_size=None,
                       open_timeout=timeout, close_timeout=CLOSE_TIMEOUT) as socket:
        assert socket.subprotocol == SUBPROTOCOL
        decoders, by_subscription = {}, {}
        while time.monotonic() < deadline:
            try:
                frame = await asyncio.wait_for(socket.recv(), deadline - time.monotonic())
            except TimeoutError:
                break
            if isinstance(frame, str):
                op = json.loads(frame)
                if op['op'] == 'serverInfo':
                    received.server_info = op
                    if request_parameters:
                        await socket.send(json.dumps({'op': 'getParameters',
                                                      'parameterNames': [], 'id': 'all'}))
                elif op['op'] == 'advertise':
                    new = []
                    for channel in op['channels']:
                        received.channels[channel['topic']] = channel
                        if channel['topic'] in topics:
                            number = len(by_subscription) + 1
                            by_subscription[number] = channel['topic']
                            decoders[channel['topic']] = _decoder(channel)
                            new.append({'id': number, 'channelId': channel['id']})
                    if new:
                        await socket.send(json.dumps({'op': 'subscribe', 'subscriptions': new}))
                elif op['op'] == 'parameterValues':
                    received.parameters.append(op)
            elif frame[0] == MESSAGE_DATA:
                subscription, log_time = struct.unpack_from('<IQ', frame, 1)
                topic = by_subscription[subscription]
                message = decoders[topic](bytes(frame[13:]))
                received.messages.setdefault(topic, []).append((log_time, message))
            elif frame[0] == TIME:
                received.times.append(struct.unpack_from('<Q', frame, 1)[0])
            if enough(received):
                break
    return received


def collect(port, topics, enough, timeout=60.0, request_parameters=False):
    """Connect to the server on 127.0.0.1:``port``, subscribe to ``topics`` as they are
    advertised and read until ``enough(received)`` or ``timeout`` seconds; the Received."""
    return asyncio.run(_collect(port, set(topics), enough, timeout, request_parameters))


def refused(port, subprotocol):
    """The HTTP status with which the server refuses a handshake for ``subprotocol``, or None
    if it accepts it."""
    async def attempt():
        try:
            async with connect(f'ws://127.0.0.1:{port}', subprotocols=[subprotocol],
                               open_timeout=30):
                return None
        except websockets.exceptions.InvalidStatus as error:
            return error.response.status_code
    return asyncio.run(attempt())


def stamp_ns(timestamp):
    """Integer ns of a google.protobuf.Timestamp."""
    return timestamp.seconds * 1_000_000_000 + timestamp.nanos
