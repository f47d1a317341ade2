"""The recorded states as a table: ``twodisk-inspect run.mcap --csv states.csv --npz states.npz``.

One row per sample: the stamps shared by pose, both contacts and the rolling state (the
samples the checks use, :func:`~twodisk_ros.inspector.series.join_samples`; at a stamp recorded
twice the first message counts).  The values are the recorded ones, unchanged (the
quaternion as recorded, not normalised).  Columns (:data:`COLUMNS`), SI units:

=====================  =====  ==========================================================
``t``                  s      stamp minus the first stamp of the recording
``stamp``              ns     header stamp (integer)
``G_x G_y G_z``        m      centre of mass G, world frame
``q_x q_y q_z q_w``    1      orientation quaternion, body → world
``A_x A_y A_z``        m      contact point A (``contact_a``)
``B_x B_y B_z``        m      contact point B (``contact_b``)
``theta psi u``        rad    θ, ψ and the phase u (``rolling_state`` positions)
``theta_rate`` …       rad/s  θ̇, ψ̇, u̇ (``rolling_state`` velocities; NaN if not recorded)
``F_A_x`` … ``F_B_z``  N      the ground's force on the body at A and at B (``wrench_a``,
                              ``wrench_b``); NaN where the recording has no wrench at
                              that stamp (older recordings, the tail of a cut file)
=====================  =====  ==========================================================

The force columns are always there, so every file has the same 27 columns.

CSV: one header line ``t [s],stamp [ns],G_x [m],...`` (name and unit), then one line per
sample, floats written as Python's ``repr`` (the shortest text that reads back to the same
float64), NaN as ``nan``.  Read it with ``pandas.read_csv(path,
float_precision='round_trip')`` (exact floats) or ``numpy.genfromtxt(path, delimiter=',',
names=True)`` (names lose their brackets: ``t_s``, ``theta_rate_rads``; stamps beyond 2^53 ns
lose their last digits as floats) or ``numpy.loadtxt(path, delimiter=',', skiprows=1)``.

NPZ: one array per column under its name (``t``, ``stamp`` int64, ``G_x``, ...), and
``columns`` and ``units``: string arrays of the names and their units, in column order.
``numpy.load(path)`` reads it (no pickle).
"""

import numpy as np

from ..outputs import replacing
from .series import values_at

__all__ = ['COLUMNS', 'state_table', 'write_csv', 'write_npz', 'write_outputs']

#: (name, unit) of every column, in order.
COLUMNS = (
    ('t', 's'), ('stamp', 'ns'),
    ('G_x', 'm'), ('G_y', 'm'), ('G_z', 'm'),
    ('q_x', '1'), ('q_y', '1'), ('q_z', '1'), ('q_w', '1'),
    ('A_x', 'm'), ('A_y', 'm'), ('A_z', 'm'),
    ('B_x', 'm'), ('B_y', 'm'), ('B_z', 'm'),
    ('theta', 'rad'), ('psi', 'rad'), ('u', 'rad'),
    ('theta_rate', 'rad/s'), ('psi_rate', 'rad/s'), ('u_rate', 'rad/s'),
    ('F_A_x', 'N'), ('F_A_y', 'N'), ('F_A_z', 'N'),
    ('F_B_x', 'N'), ('F_B_y', 'N'), ('F_B_z', 'N'),
)
_ROWS_PER_WRITE = 20_000


def state_table(inspection):
    """The columns of :data:`COLUMNS` for the samples of an inspection.

    Parameters
    ----------
    inspection : Inspection
        From :func:`~twodisk_ros.inspector.inspect_recording`.

    Returns
    -------
    dict of str to numpy.ndarray
        In column order; ``stamp`` int64, the others float64; empty arrays if no sample.
    """
    samples, sources = inspection.samples, inspection.sources
    if samples is None:
        stamps = np.zeros(0, dtype=np.int64)
        table = {'t': np.zeros(0), 'stamp': stamps}
        table.update({name: np.zeros(0) for name, _ in COLUMNS[2:]})
        return table
    stamps = np.asarray(samples.stamp_ns, dtype=np.int64)
    quaternion, _ = values_at(sources.get('pose'), 'quaternion', stamps)
    forces = {role: values_at(sources.get(role), 'force', stamps)[0]
              for role in ('wrench_a', 'wrench_b')}
    table = {'t': np.asarray(samples.t, dtype=float), 'stamp': stamps}
    for prefix, values, axes in (('G', samples.position_g, 'xyz'), ('q', quaternion, 'xyzw'),
                                 ('A', samples.contact_a, 'xyz'),
                                 ('B', samples.contact_b, 'xyz'),
                                 ('F_A', forces['wrench_a'], 'xyz'),
                                 ('F_B', forces['wrench_b'], 'xyz')):
        table.update({f'{prefix}_{axis}': values[:, k] for k, axis in enumerate(axes)})
    for k, name in enumerate(('theta', 'psi', 'u')):
        table[name] = samples.angles[:, k]
        table[f'{name}_rate'] = samples.rates[:, k]
    return {name: np.ascontiguousarray(table[name], dtype=np.int64 if name == 'stamp'
                                       else float) for name, _ in COLUMNS}


def write_csv(path, table):
    """Write ``table`` as CSV to ``path`` (a header of ``name [unit]``; floats by ``repr``)."""
    header = ','.join(f'{name} [{unit}]' for name, unit in COLUMNS)
    rows = len(table['stamp'])
    with open(path, 'w', encoding='utf-8', newline='\n') as stream:
        stream.write(header + '\n')
        for start in range(0, rows, _ROWS_PER_WRITE):
            stop = min(rows, start + _ROWS_PER_WRITE)
            columns = [list(map(str if name == 'stamp' else repr,
                                table[name][start:stop].tolist())) for name, _ in COLUMNS]
            stream.write(''.join(','.join(row) + '\n' for row in zip(*columns)))


def write_npz(path, table):
    """Write ``table`` as an uncompressed NPZ to ``path``, with ``columns`` and ``units``."""
    names = [name for name, _ in COLUMNS]
    with open(path, 'wb') as stream:
        np.savez(stream, **{name: table[name] for name in names},
                 columns=np.array(names), units=np.array([unit for _, unit in COLUMNS]))


def write_outputs(inspection, csv=None, npz=None):
    """Write the CSV and/or NPZ of an inspection, each through a temporary file.

    The paths must have been checked with :func:`twodisk_ros.outputs.check_output`; an
    existing file is replaced only when complete (OSError on failure, old file kept).
    """
    if not (csv or npz):
        return
    table = state_table(inspection)
    for path, write in ((csv, write_csv), (npz, write_npz)):
        if path:
            with replacing(path) as temporary:
                write(temporary, table)
