"""The YAML that rosbag2 (Jazzy) stores in MCAP: QoS profiles and the bag metadata.

rosbag2 writes this YAML with yaml-cpp (``YAML::Dump``: block style, sequences indented under
their key); the functions here emit the same text, from ``rosbag2_storage`` (qos.cpp,
yaml.hpp) in Jazzy.
"""

import os
import re

import yaml

__all__ = ['BAG_METADATA_VERSION', 'ROS_DISTRO', 'bag_metadata', 'dump_yaml', 'qos_node',
           'qos_profiles_yaml']

BAG_METADATA_VERSION = 9  # rosbag2_storage BagMetadata::version in Jazzy
ROS_DISTRO = 'jazzy'
_INT64_MAX = 2**63 - 1

# YAML as yaml-cpp's YAML::Dump emits it (block style, sequences indented under their key).

_PLAIN = re.compile(r'[A-Za-z0-9_./][A-Za-z0-9_./ -]*')
_ESCAPES = {'"': '\\"', '\\': '\\\\'}


def _quoted(text):
    """Return a double-quoted YAML scalar, escaping all but printable ASCII."""
    out = []
    for char in text:
        code = ord(char)
        if char in _ESCAPES:
            out.append(_ESCAPES[char])
        elif 0x20 <= code < 0x7f:
            out.append(char)
        elif code <= 0xffff:
            out.append(f'\\u{code:04x}')
        else:
            out.append(f'\\U{code:08x}')
    return '"' + ''.join(out) + '"'


def _scalar(value):
    """Format one YAML scalar: plain where that reads back as the same string, else quoted."""
    if value is None:
        return '~'
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return str(value)
    text = str(value)
    if _PLAIN.fullmatch(text) and not text.endswith(' ') and _reads_back(text):
        return text
    return _quoted(text)


def _reads_back(text):
    """True if ``text`` written plain is read as the same string (``...`` ends a document)."""
    try:
        return yaml.safe_load(text) == text
    except yaml.YAMLError:
        return False


def _lines(value, indent):
    """Return the block YAML lines of a dict or a list at ``indent`` spaces."""
    pad = ' ' * indent
    out = []
    if isinstance(value, dict):
        for key, item in value.items():
            if isinstance(item, (dict, list)) and item:
                out.append(f'{pad}{key}:')
                out += _lines(item, indent + 2)
            else:
                out.append(f'{pad}{key}: {_empty(item)}')
    else:
        for item in value:
            if isinstance(item, (dict, list)) and item:
                sub = _lines(item, indent + 2)
                sub[0] = f'{pad}- {sub[0][indent + 2:]}'
                out += sub
            else:
                out.append(f'{pad}- {_empty(item)}')
    return out


def _empty(value):
    """Format a scalar, or an empty container as yaml-cpp does (``[]`` / ``{}``)."""
    if isinstance(value, list):
        return '[]'
    if isinstance(value, dict):
        return '{}'
    return _scalar(value)


def dump_yaml(value):
    """Dump a dict or list like ``YAML::Dump`` (no trailing newline)."""
    return '\n'.join(_lines(value, 0))


def _rmw_time(duration):
    """Return an ``rmw_time_t``-like ``{sec, nsec}`` mapping of an rclpy ``Duration``."""
    sec, nsec = divmod(int(duration.nanoseconds), 10**9)
    return {'sec': sec, 'nsec': nsec}


def qos_node(qos):
    """Return the YAML node of one QoS profile (version 9: policies as rmw strings)."""
    return {
        'history': qos.history.name.lower(),
        'depth': int(qos.depth),
        'reliability': qos.reliability.name.lower(),
        'durability': qos.durability.name.lower(),
        'deadline': _rmw_time(qos.deadline),
        'lifespan': _rmw_time(qos.lifespan),
        'liveliness': qos.liveliness.name.lower(),
        'liveliness_lease_duration': _rmw_time(qos.liveliness_lease_duration),
        'avoid_ros_namespace_conventions': bool(qos.avoid_ros_namespace_conventions),
    }


def qos_profiles_yaml(profiles):
    """Return ``offered_qos_profiles`` channel metadata as rosbag2 Jazzy writes it.

    Parameters
    ----------
    profiles : sequence of rclpy.qos.QoSProfile
        The offered profiles of the topic's publishers (or objects with the same
        attributes: rclpy itself is not needed).

    Returns
    -------
    str
        The YAML sequence, e.g. ``'- history: keep_last\\n  depth: 10\\n  ...'``.
    """
    return dump_yaml([qos_node(qos) for qos in profiles])


def bag_metadata(path, topics, message_count, first_ns, last_ns):
    """The ``rosbag2`` metadata record of a recording: ``{'serialized_metadata': yaml}``.

    Parameters
    ----------
    path : str
        The file (its base name is the bag's relative file path).
    topics : list of dict
        Per topic: ``name``, ``type`` (``pkg/msg/Type``), ``qos`` (a QoS profile),
        ``type_hash`` and ``message_count``.
    message_count : int
    first_ns, last_ns : int or None
        First and last log time (ns); None for an empty recording.
    """
    if first_ns is None:
        start, duration = _INT64_MAX, 0  # std::chrono::nanoseconds::max(), as rosbag2
    else:
        start, duration = first_ns, last_ns - first_ns
    name = os.path.basename(path)
    topic_list = [
        {
            'topic_metadata': {
                'name': topic['name'],
                'type': topic['type'],
                'serialization_format': 'cdr',
                'offered_qos_profiles': [qos_node(topic['qos'])],
                'type_description_hash': topic['type_hash'],
            },
            'message_count': topic['message_count'],
        }
        for topic in topics
    ]
    bag = {
        'version': BAG_METADATA_VERSION,
        'storage_identifier': 'mcap',
        'duration': {'nanoseconds': duration},
        'starting_time': {'nanoseconds_since_epoch': start},
        'message_count': message_count,
        'topics_with_message_count': topic_list,
        'compression_format': '',
        'compression_mode': '',
        'relative_file_paths': [name],
        'files': [{
            'path': name,
            'starting_time': {'nanoseconds_since_epoch': start},
            'duration': {'nanoseconds': duration},
            'message_count': message_count,
        }],
        'custom_data': None,
        'ros_distro': ROS_DISTRO,
    }
    return {'serialized_metadata': dump_yaml(bag)}
