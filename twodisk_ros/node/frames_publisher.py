"""The body in ROS tools: ``/tf_static`` (the disk frames) and ``robot_description`` (URDF).

Both are latched as ``robot_state_publisher`` latches them: transient-local QoS, keep last 1,
so a subscriber that joins later (RViz, Foxglove, a tf2 listener) receives the current one.
Each is sent at the run's first sample and again at the first sample after a parameter
change that alters it, stamped with that sample's stamp (ns); the recorder gets the same
bytes at that stamp, before the sample's messages.

- ``/tf_static`` (tf2_msgs/TFMessage): one message with two transforms, parent
  ``body_frame``, children ``{body_frame}_disk_a`` (disk 1, contact A) and
  ``{body_frame}_disk_b`` (disk 2, contact B): each disk's centre and plane
  (:mod:`twodisk_ros.model.frames`). They change with ``delta`` and ``body_frame``.
- ``robot_description`` (std_msgs/String): the URDF of :mod:`twodisk_ros.model.urdf` with
  its meshes (binary STL in the mesh cache, ``file://`` URIs). It changes with the shape
  (a, b, delta), the mass model (mass, mass_model, principal_moments) and ``body_frame``.

"Alters" is judged on the content itself (the transforms, the URDF text), so a change that
leaves it equal sends nothing. A renamed ``body_frame`` leaves the old static frames in the
buffers of running tf2 listeners (tf2 keeps static frames for ever); the new ones are
complete on their own.

``/tf`` itself, the moving body frame at ``rate``, is one of the node's sampled topics
(:data:`TF_TOPIC`, encoded with the pose from the same arrays: see ``roller.py``).
"""

from dataclasses import dataclass

from geometry_msgs.msg import Quaternion, Transform, TransformStamped, Vector3
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ..recordings import cdr
from ..model.frames import disk_frames
from ..model.urdf import body_description, robot_description
from ..outputs import OutputError
from . import messages

__all__ = ['DESCRIPTION_TOPIC', 'LATCHED_QOS', 'TF_QOS', 'TF_STATIC_TOPIC', 'TF_TOPIC',
           'Description', 'LatchedTopics', 'TFMessage', 'describe']

TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'
DESCRIPTION_TOPIC = 'robot_description'
#: tf2_ros's DynamicBroadcasterQoS: reliable, volatile, keep last 100.
TF_QOS = QoSProfile(depth=100)
#: tf2_ros's StaticBroadcasterQoS and robot_state_publisher's: transient local, keep last 1.
LATCHED_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
TYPES = {TF_STATIC_TOPIC: TFMessage, DESCRIPTION_TOPIC: String}


@dataclass(frozen=True)
class Description:
    """What the latched topics hold for some settings (compared to decide what to resend).

    ``static``: per disk frame (parent, child, translation (m), quaternion x, y, z, w) as
    tuples of floats; ``urdf``: the URDF text; ``problem``: why it has no meshes (one line),
    or None.
    """

    static: tuple
    urdf: str
    problem: str | None = None


def describe(settings, body, mass):
    """The :class:`Description` of checked ``settings``, their body and its
    :class:`~twodisk_ros.physics.mass.models.MassProperties` (the simulation's).

    The URDF's meshes are written to the mesh cache if missing
    (:func:`~twodisk_ros.model.urdf.body_description`). If the cache cannot be written
    (a read-only home), the URDF has no meshes (links, joints and inertia only: viewers show
    the frames) and ``problem`` says why, for the node's log: the motion does not need them.
    """
    frames = tuple((f.parent_frame_id, f.child_frame_id, tuple(map(float, f.translation)),
                    tuple(map(float, f.quaternion)))
                   for f in disk_frames(body, settings.body_frame))
    try:
        return Description(frames, body_description(body, mass, settings.body_frame))
    except OutputError as error:
        return Description(frames, robot_description(body, mass, settings.body_frame),
                           f'robot_description without meshes: {error}')


def _static_message(static, stamp_ns):
    """The TFMessage of ``Description.static``, every transform stamped ``stamp_ns``."""
    return TFMessage(transforms=[
        TransformStamped(header=messages.header(parent, stamp_ns), child_frame_id=child,
                         transform=Transform(translation=Vector3(x=t[0], y=t[1], z=t[2]),
                                             rotation=Quaternion(x=q[0], y=q[1], z=q[2],
                                                                 w=q[3])))
        for parent, child, t, q in static])


class LatchedTopics:
    """The publishers of ``/tf_static`` and ``robot_description`` and what they last sent.

    Parameters
    ----------
    node : rclpy.node.Node
        Creates the publishers.
    description : Description
        What to send at the first sample.
    """

    def __init__(self, node, description):
        self.publishers = {topic: node.create_publisher(kind, topic, LATCHED_QOS)
                           for topic, kind in TYPES.items()}
        self._sent = {}             # topic -> the content last sent
        self.due = True             #: a topic's content differs from what it last sent
        self.take(description)

    def take(self, description):
        """Send ``description`` at the next :meth:`send` (only what differs from the last)."""
        self._next = {TF_STATIC_TOPIC: description.static,
                      DESCRIPTION_TOPIC: description.urdf}
        self.due = any(self._sent.get(topic) != content
                       for topic, content in self._next.items())

    def send(self, stamp_ns, record=None):
        """Publish what changed, stamped ``stamp_ns``; ``record(topic_name, data, stamp_ns)``.

        Returns the topics sent.
        """
        sent = []
        for topic, content in self._next.items():
            if self._sent.get(topic) == content:
                continue
            if topic == TF_STATIC_TOPIC:
                data = cdr.serialize(_static_message(content, stamp_ns))
            else:
                data = cdr.serialize(String(data=content))
            publisher = self.publishers[topic]
            publisher.publish(data)
            if record is not None:
                record(publisher.topic_name, data, stamp_ns)
            self._sent[topic] = content
            sent.append(topic)
        self.due = False
        return sent
