"""Shared by the CDR tests: decoding with mcap-ros2-support, an independent decoder."""

from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory

from twodisk_ros.recordings import msgdefs

_MCAP_DECODERS = {}


def mcap_decode(data, name):
    if name not in _MCAP_DECODERS:
        schema = Schema(id=1, name=name, encoding='ros2msg', data=msgdefs.full_text(name))
        _MCAP_DECODERS[name] = DecoderFactory().decoder_for('cdr', schema)
    return _MCAP_DECODERS[name](data)
