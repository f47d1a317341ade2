"""Recordings: MCAP files in the layout rosbag2 (Jazzy) writes, and a tolerant reader.

- :mod:`~twodisk_ros.recordings.writer`: :class:`McapRecorder` (needs rclpy only for its defaults);
- :mod:`~twodisk_ros.recordings.reader`: :func:`read_recording` (mcap and mcap-ros2-support only);
- :mod:`~twodisk_ros.recordings.mcap_scan`: the records of a cut or damaged file (recovery rule);
- :mod:`~twodisk_ros.recordings.cdr_decode`: the reader's message decoders (mcap_ros2's results, faster);
- :mod:`~twodisk_ros.recordings.msgdefs`: the ``ros2msg`` schema texts;
- :mod:`~twodisk_ros.recordings.rosbag2_metadata`: the QoS and bag-metadata YAML;
- :mod:`~twodisk_ros.recordings.errors`: :class:`RecordingError`.
"""

from .errors import RecordingError, RecordingExistsError
from .reader import RecordedMessage, Recording, TopicInfo, read_recording
from .writer import DEFAULT_CHUNK_SIZE, McapRecorder

__all__ = ['DEFAULT_CHUNK_SIZE', 'McapRecorder', 'RecordedMessage', 'Recording',
           'RecordingError', 'RecordingExistsError', 'TopicInfo', 'read_recording']
