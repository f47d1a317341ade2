"""The per-sample topics of a block of samples, encoded to CDR in one vectorised step."""

import numpy as np

from ..recordings import cdr
from . import messages, sim_clock
from .frames_publisher import TF_TOPIC

__all__ = ['encode_block']


def encode_block(first, sample, stamps, settings, wanted, clock_wanted):
    """CDR bytes of the per-sample topics somebody wants: {topic: [bytes per sample]}.

    ``first``: the global tick of the block's first sample; ``wanted(topic)``: True if the
    topic is recorded or subscribed; ``clock_wanted``: /clock has a subscriber. /clock comes
    first (it is published before each sample's messages) and may skip samples (None).
    Returns (encoded, {topic: messages built}).
    """
    frame = settings.frame_id
    encoded, built = {}, {}
    if clock_wanted:
        column = sim_clock.encode_clock_column(first, stamps,
                                               sim_clock.clock_step(settings.rate))
        encoded[sim_clock.CLOCK_TOPIC] = column
        built[sim_clock.CLOCK_TOPIC] = sum(x is not None for x in column)
    encoders = {
        'pose': lambda: cdr.encode_pose_stamped(stamps, frame, sample.position_g,
                                                sample.quaternion),
        TF_TOPIC: lambda: cdr.encode_tf_message(stamps, frame, settings.body_frame,
                                                sample.position_g, sample.quaternion),
        'contact_a': lambda: cdr.encode_point_stamped(stamps, frame, sample.contact_a),
        'contact_b': lambda: cdr.encode_point_stamped(stamps, frame, sample.contact_b),
        'rolling_state': lambda: cdr.encode_joint_state(
            stamps, messages.JOINT_NAMES,
            np.column_stack([sample.theta, sample.psi, sample.phase]),
            np.column_stack([sample.theta_rate, sample.psi_rate, sample.phase_rate])),
    }
    if sample.forces is not None:   # (a subscriber may appear after the sampling)
        encoders['wrench_a'] = lambda: cdr.encode_wrench_stamped(stamps, frame,
                                                                 sample.forces.force_a)
        encoders['wrench_b'] = lambda: cdr.encode_wrench_stamped(stamps, frame,
                                                                 sample.forces.force_b)
    for topic, encode in encoders.items():
        if wanted(topic):
            encoded[topic] = encode()
            built[topic] = len(encoded[topic])
    return encoded, built
