"""The superellipse exponent n as the sweep's third axis (issue 20).

References, none of them the code under test:

- n = 2 is the batched ellipse sweep: its plane equals, bit for bit, the batched path called directly on
  the same blocks (what a task computed before the axis existed) and a sweep of n = 2 alone;
- the per-body general path is exercised with a fake body factory (the ellipse EllipseBody
  and its closed-form mass model for every n): its values must then be the ellipse's, which
  the batched closed forms compute by other code (arrays, fixed-angle equilibria, the
  roll-over speed from m(u*) and ω_u instead of I_AB);
- a real n = 4 body (LaminaBody) against
  the closed-form symmetric equilibria and the superellipse's Γ-function area moments.

Dask runs in this process (threads, in-process transport, no dashboard) where the fake factory must
reach the tasks: a monkeypatch is seen by threads, not by worker processes.
"""

import math
import re

import numpy as np
import pytest

from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.sweep import general
from twodisk_ros.sweep.batch import Ellipses
from twodisk_ros.sweep.cli import main
from twodisk_ros.sweep.dataset import read_sweep
from twodisk_ros.sweep.chunks import quantities, timed_chunk
from twodisk_ros.sweep.general import Laminae
from twodisk_ros.sweep.quantities import VARIABLES
from twodisk_ros.sweep.request import EXPONENT_RANGE, SweepError, exponent_values
from twodisk_ros.sweep.run import SweepSpec, run_sweep

# both stable families (b/a = 1: -1 at Δ/a = 0.25, 0.5 and +1 at 0.75; b/a = 1.5: +1); Δ/a = 1
# masked
B, D = np.linspace(1.0, 1.5, 2), np.linspace(0.25, 1.0, 4)
#: claim (docs/sweeps.md "The exponent axis"): the general path on ellipse bodies agrees with
#: the batched closed forms to <= 1e-12 relative (measured 4e-14: lift-off speed, mu_required)
GENERAL_RTOL = 1e-12
#: variables whose meaning differs on the general path (checked one by one below)
OWN_MEANING = {'stability_margin'}


def fake_body(b, d, n):
    """The ellipse (a, b, Δ) = (1, b, d) whatever n: a RollingBody with closed forms."""
    return EllipseBody(1.0, b, d)


def fake_mass(model, body):
    return mass_properties(model, 1.0, body.b, body.delta, 1.0)


@pytest.fixture
def fake_factories(monkeypatch):
    monkeypatch.setattr(general, 'superellipse_body', fake_body)
    monkeypatch.setattr(general, 'lamina_mass', fake_mass)


@pytest.fixture(scope='module')
def client():
    """A Dask client on threads of this process (one worker, in-process transport: nothing
    listens on the network; no dashboard)."""
    import logging
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                           dashboard_address=None,
                           silence_logs=logging.CRITICAL,
                           scheduler_kwargs={'dashboard': False,
                                             'dashboard_address': '127.0.0.1:0'})
    client = Client(cluster, set_as_default=False)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


@pytest.fixture(scope='module')
def blocks_once():
    """Each block's bodies computed once in this module (dask_helpers.blocks_computed_once;
    the key names the exponent and the general path's factories, so the fake ellipse bodies
    and real ones never mix). The value claims hold against references computed without it
    (_batched_reference, the batched closed forms) by the first computation of each block;
    what a repeat checks is its own path: the other file format's round trip ([.zarr] after
    [.nc] of the same mixed sweep), the n = 2 grid alone as a sweep of its own (its blocks
    are the mixed sweep's n = 2 blocks), and which blocks a stopped and resumed store holds
    (a block written twice, at the wrong place or not at all still differs from the
    reference run's). Saves the general path's bodies of the repeated sweeps (~3 s of CPU)."""
    from dask_helpers import blocks_computed_once
    with blocks_computed_once():
        yield


def _spec(exponents, chunk=3):
    return SweepSpec(B, D, chunk_size=chunk, exponent=np.array(exponents, dtype=float))


def _batched_reference(spec):
    """The n = 2 grid as the batched tasks compute it: the ellipse batch of each block."""
    out = {name: np.full(spec.shape[1:], np.nan) for name in VARIABLES}
    out['failure'] = np.full(spec.shape[1:], '', dtype=object)
    for block in spec.blocks():
        if spec.block_exponent(block) != 2.0:
            continue
        result = quantities(Ellipses(*spec.block_points(block)))
        plane = block[1:]
        for name in out:
            out[name][plane] = np.asarray(result[name]).reshape(out[name][plane].shape)
    return out


# -- the axis, its blocks, its input ---------------------------------------------------------

def test_exponent_range_is_the_laminas():
    from twodisk_ros.physics.laminae.shapes import SUPERELLIPSE_EXPONENT
    assert EXPONENT_RANGE == SUPERELLIPSE_EXPONENT


def test_blocks_hold_one_exponent_and_cover_the_grid_once():
    spec = _spec([2.0, 3.5, 10.0], chunk=5)
    covered = np.zeros(spec.shape, dtype=int)
    n, b, d = spec.points()
    for block, flat in zip(spec.blocks(), spec.chunks()):
        covered[block] += 1
        assert block[0].stop - block[0].start == 1 and covered[block].size <= 5
        assert np.all(n[flat] == spec.block_exponent(block))
        np.testing.assert_array_equal(b[flat], spec.block_points(block)[0])
        np.testing.assert_array_equal(d[flat], spec.block_points(block)[1])
    assert np.all(covered == 1)
    # the n = 2 plane is cut as the ellipse-only grid is
    alone = [blk[1:] for blk in _spec([2.0], chunk=5).blocks()]
    assert [blk[1:] for blk in spec.blocks() if spec.block_exponent(blk) == 2.0] == alone
    # resume state is never shared between different exponent axes
    assert _spec([2.0, 4.0]).manifest() != _spec([2.0, 4.5]).manifest()
    assert _spec([2.0]).manifest()['exponent'] == [(2.0).hex()]


@pytest.mark.parametrize('values, words', [
    (['1.5'], 'within [2, 100]'), (['100.5'], 'got 100.5'), (['nan'], 'finite'),
    (['4', '3'], 'strictly increasing'), (['4', '4'], 'strictly increasing'),
])
def test_exponent_values_refuse_in_one_line(values, words):
    with pytest.raises(SweepError, match=re.escape(words)) as error:
        exponent_values('--exponent', values)
    assert '\n' not in str(error.value)


@pytest.mark.parametrize('argv, words', [
    (['--exponent', '1.99'], '--exponent: the superellipse exponent must be finite and within'),
    (['--exponent', 'four'], "--exponent must be a number, got 'four'"),
    (['--exponent', '2', '101'], 'got 101.0'),
    (['--exponent', '3', '2'], 'strictly increasing'),
    (['--exponent-range', '2', '200', '4'], '--exponent-range: the superellipse exponent'),
    (['--exponent-range', '4', '2', '3'], 'reversed range'),
    (['--exponent-range', '2', '4', '0'], 'N must be'),
    (['--exponent', '2', '--exponent-range', '2', '4', '3'], 'not allowed with'),
    (['--exponent'], 'expected at least one argument'),
])
def test_bad_exponents_are_one_line_exit_2_before_dask(argv, words, tmp_path, capsys):
    status = main(['--b-over-a', '0.5', '1.5', '3', '--delta-over-a', '0.25', '1', '4',
                   '--out', str(tmp_path / 'x.nc'), *argv])
    err = capsys.readouterr().err
    assert status == 2 and err.count('\n') == 1 and words in err, err
    assert 'Traceback' not in err and list(tmp_path.iterdir()) == []


# -- n = 2 is the batched ellipse sweep; the exponent round trips ---------------------------------------

@pytest.mark.parametrize('suffix', ['.nc', '.zarr'])
def test_mixed_sweep_keeps_n2_bitwise_and_round_trips_the_exponent(client, fake_factories,
                                                                   blocks_once, tmp_path,
                                                                   suffix):
    exponents = [2.0, 2.0 + 2**-40, 7.25]    # one just above 2: the general path already
    spec = _spec(exponents)
    run = run_sweep(spec, client, out=tmp_path / f'map{suffix}', progress=None)
    dataset = read_sweep(tmp_path / f'map{suffix}')
    assert dataset['exponent'].values.tolist() == exponents             # bitwise
    assert dataset['theta_max'].dims == ('exponent', 'b_over_a', 'delta_over_a')
    assert dataset['exponent'].attrs['long_name'] == 'n'
    reference = _batched_reference(spec)
    plane = dataset.sel(exponent=2.0)
    for name in (*VARIABLES, 'failure'):
        np.testing.assert_array_equal(plane[name].values, reference[name], err_msg=name)
    alone = run_sweep(_spec([2.0]), client, progress=None).dataset
    for name in (*VARIABLES, 'failure'):
        np.testing.assert_array_equal(alone[name].values[0], reference[name], err_msg=name)
    # an n = 2 grid alone has the variables' attributes of before the axis
    assert 'general_path' not in alone['stable_family'].attrs
    assert np.asarray(alone['stable_family'].attrs['flag_values']).tolist() == [-1, 0, 1]
    # the general path's planes (fake ellipse bodies) hold the ellipse's values
    for n in exponents[1:]:
        other = dataset.sel(exponent=n)
        np.testing.assert_array_equal(other['failure'].values, reference['failure'])
        for name in set(VARIABLES) - OWN_MEANING:
            np.testing.assert_allclose(other[name].values, reference[name], rtol=GENERAL_RTOL,
                                       atol=0.0, err_msg=f'{n} {name}')
        assert np.all(np.isnan(other['stability_margin'].values))
    assert 'NaN' in dataset['stability_margin'].attrs['general_path']
    assert np.asarray(dataset['stable_family'].attrs['flag_values']).tolist() == [-1, 0, 1, 2]
    assert run.masked == len(exponents) * len(B)          # the Δ/a = 1 column of each plane


def test_zarr_sweep_of_several_exponents_resumes_bitwise(client, fake_factories, blocks_once,
                                                         tmp_path):
    spec = _spec([2.0, 4.0])
    reference = run_sweep(spec, client, progress=None).dataset
    store = tmp_path / 'map.zarr'

    class Stop(Exception):
        pass

    def stop(index, computed):
        if computed == 3:
            raise Stop

    with pytest.raises(Stop):
        run_sweep(spec, client, out=store, progress=None, on_chunk=stop)
    again = run_sweep(spec, client, out=store, progress=None, overwrite=False)
    assert again.resumed >= 3 and again.resumed + again.computed == len(spec.blocks())
    resumed = read_sweep(store)
    for name in (*VARIABLES, 'failure', 'exponent'):
        np.testing.assert_array_equal(resumed[name].values, reference[name].values, name)


def test_general_path_on_an_ellipse_is_the_batched_path():
    """Laminae with an injected factory (no Dask): both families and the neutral
    line b² = 2(a² − Δ²), where stable_family is 0 and the barrier and speed are 0."""
    b = np.array([0.5, 1.5, math.sqrt(2 - 2 * 0.5**2), 1.0])
    d = np.array([0.25, 0.75, 0.5, 0.9])
    reference = quantities(Ellipses(b, d))
    got = quantities(Laminae(b, d, 3.0, body_factory=fake_body, mass_factory=fake_mass))
    assert got['failure'] == reference['failure'] == [''] * 4
    for name in set(VARIABLES) - OWN_MEANING:
        np.testing.assert_allclose(got[name], reference[name], rtol=GENERAL_RTOL, atol=0.0,
                                   err_msg=name)
    assert got['stable_family'].tolist() == [-1.0, 1.0, 0.0, 1.0]
    # the same bodies in a task's batch at n = 2 are the batched path itself
    same = timed_chunk(b, d)[0]
    for name in VARIABLES:
        np.testing.assert_array_equal(same[name], reference[name], err_msg=name)


def test_a_body_the_general_path_cannot_build_is_masked_in_one_line():
    def broken(b, d, n):
        raise ValueError(f'no superellipse with n = {n}\nsecond line')
    got = quantities(Laminae([1.0, 1.0], [0.5, 1.0], 5.0, body_factory=broken,
                             mass_factory=fake_mass))
    assert got['failure'][0] == 'body: ValueError: no superellipse with n = 5.0 second line'
    assert got['failure'][1].startswith('body: delta/a = 1.0 >= 1')
    assert all(np.isnan(got[name]).all() for name in VARIABLES)


# -- the maps --------------------------------------------------------------------------------

def test_maps_draw_one_panel_per_exponent_on_one_scale(tmp_path):
    import matplotlib.pyplot as plt
    import xarray as xr
    from twodisk_ros.plotting.sweep_maps import MAX_PANELS, plot_panels, write_maps
    exponents = np.array([2.0, 4.0, 8.0])
    values = np.arange(3 * B.size * D.size, dtype=float).reshape(3, B.size, D.size) + 1.0
    dims = ('exponent', 'b_over_a', 'delta_over_a')
    attrs = {'units': 'a', 'description': 'test values'}
    dataset = xr.Dataset({'barrier': (dims, values, attrs)},
                         coords={'exponent': exponents, 'b_over_a': B, 'delta_over_a': D})
    fig = plot_panels(dataset, 'barrier')
    try:
        panels = [ax for ax in fig.axes if ax.get_title().startswith('n = ')]
        assert [ax.get_title() for ax in panels] == ['n = 2 (ellipse)', 'n = 4', 'n = 8']
        limits = {(ax.collections[0].norm.vmin, ax.collections[0].norm.vmax) for ax in panels}
        assert limits == {(1.0, values.size)}        # one colour scale over every panel
        # the ellipse's neutral curve only where n = 2
        assert [len(ax.lines) > 0 for ax in panels] == [True, False, False]
    finally:
        plt.close(fig)
    many = dataset.reindex(exponent=np.linspace(2.0, 40.0, 20), method='nearest')
    fig = plot_panels(many, 'barrier')
    try:
        panels = [ax for ax in fig.axes if ax.get_title().startswith('n = ')]
        assert len(panels) == MAX_PANELS
        assert panels[0].get_title() == 'n = 2 (ellipse)' and panels[-1].get_title() == 'n = 40'
        assert f'{MAX_PANELS} of 20 exponents shown' in fig.get_suptitle()
    finally:
        plt.close(fig)
    assert [p.name for p in write_maps(dataset, tmp_path)] == ['barrier.png']


# -- a real superellipse (once LaminaBody is implemented) -----------------------------------

def _superellipse_plate_moments(b, n):
    """Area and ∫x² dA, ∫y² dA of |x/b|ⁿ + |y|ⁿ ≤ 1 (Γ functions; not laminae/shapes.py's code)."""
    g = math.gamma
    area = 4 * b * g(1 + 1 / n) ** 2 / g(1 + 2 / n)
    xx = 4 * b**3 * g(3 / n) * g(1 / n) / (n**2 * g(1 + 4 / n))
    yy = 4 * b * g(3 / n) * g(1 / n) / (n**2 * g(1 + 4 / n))
    return area, xx, yy


def test_a_real_superellipse_n4_body():
    """n = 4, b/a = 1, Δ/a = 0.5 through LaminaBody."""
    b, d, n = 1.0, 0.5, 4.0
    got = timed_chunk([b], [d], exponent=n)[0]
    failure = got['failure'][0]
    assert failure == ''      # LaminaBody is on main: a failing body is a failure, no skip
    from twodisk_ros.physics.stability.symmetric import symmetric_equilibria
    from twodisk_ros.physics.laminae.shapes import Superellipse
    first, turning, side = symmetric_equilibria(Superellipse(1.0, b, n), d)
    # claim (issue 20): the general path is exact to <= 1e-11 of the size (size ~ 1.5 a)
    size = 1.5
    # flat vertices: every symmetric pose a local minimum (stability/symmetric.py)
    assert (first.stability, side.stability) == ('stable', 'stable')
    assert got['stable_family'][0] == 2.0
    # the lowest pose rests on the side vertices: z_G = w/√2 with w = b (closed form)
    assert abs(got['height_min'][0] - b / math.sqrt(2)) <= 1e-11 * size
    assert got['height_max'][0] >= first.height - 1e-11 * size
    assert math.isnan(got['stability_margin'][0]) and math.isnan(got['oscillation_period'][0])
    # a body symmetric under both mirrors rolls straight on average: 2π per cycle
    assert abs(got['cycle_heading'][0] - 2 * math.pi) <= 1e-11 * 2 * math.pi
    # roll-over speed: ½ I_AB ω² = M g barrier at the side vertices, I_AB from the plates'
    # Γ-function moments (laminae model, M = 1: two plates of 1/2); contacts A = (b, −Δ, 0)
    # and B = (0, Δ, −b) (G at the midpoint), axis AB
    area, xx, yy = _superellipse_plate_moments(b, n)
    m = 0.5
    i_plate1 = m / area * np.diag([yy, xx, xx + yy])        # disk 1 in x3 = 0, about C1
    i_plate2 = m / area * np.diag([xx + yy, xx, yy])        # disk 2 in x1 = 0, about C2
    shift = m * (d**2 * (np.eye(3) - np.outer([0, 1, 0], [0, 1, 0])))
    inertia = i_plate1 + i_plate2 + 2 * shift
    a_pt, b_pt = np.array([b, -d, 0.0]), np.array([0.0, d, -b])
    axis = (b_pt - a_pt) / np.linalg.norm(b_pt - a_pt)
    arm = np.cross(axis, -a_pt)
    i_ab = axis @ inertia @ axis + arm @ arm
    expected = math.sqrt(2 * got['barrier'][0] / i_ab)
    # claim: 1e-9 relative. The laminae model is exact to rounding and the barrier to
    # ~1e-11 a, but on a flat vertex z_G is so flat that the equilibrium's contact is found
    # 2.5e-5 a along the rim from the vertex (measured: θ = 1.570772 for π/2), which moves
    # I_AB by 4e-10 relative and the speed by 2e-10 (measured 1.9e-10)
    assert got['rollover_speed'][0] == pytest.approx(expected, rel=1e-9)
