"""Test-suite settings shared by every module.

Under CI (``CI=true``) hypothesis draws the same examples on every run (``derandomize``), so
a submission's verdict does not depend on luck; a developer's runs keep exploring new
examples (and keep the failures they find in .hypothesis/).

The mesh cache (``$XDG_CACHE_HOME/twodisk_ros/meshes``, default ``~/.cache/...``) is a
temporary directory per test process, removed at its end: the nodes, viewers and URDF
builders that tests run, in this process or as subprocesses (their environments are copies
of ``os.environ``), never write into the user's cache. Set here, before any test module is
imported, so that module-level environment copies hold it too.

The cyclic garbage collector runs after 50 000 net allocations of container objects instead
of 700: with every test module imported a worker's heap is large, and the default spent ~7 %
of the in-process time of the physics tests in ~2 400 collections (3.5 s of 48 s measured on
three of their files; 0.5 s in 13 collections after). Reference counting still frees
everything that is not in a cycle at once; cycles wait a little longer.

The test files run costliest first (:func:`pytest_collection_modifyitems`), each file's tests
in their own order: ``make test`` hands whole files to its two workers (``--dist loadfile
--no-loadscope-reorder``) in this order, so the last files to start are short ones and the
workers end together (ordered by their number of tests instead, the last files were the
browser's and the clock's, and one worker ended 10 s after the other). The costs are the
seconds per file measured on a fresh clone (tests/file_costs.json; a file not listed counts
as the median): stale numbers only cost balance, never a result.
"""

import gc
import json
import os
from pathlib import Path
import shutil
import statistics
import tempfile

from hypothesis import settings

gc.set_threshold(50_000, 20, 100)

MESH_CACHE_HOME = tempfile.mkdtemp(prefix='twodisk-test-cache-')
os.environ['XDG_CACHE_HOME'] = MESH_CACHE_HOME


def pytest_unconfigure(config):
    shutil.rmtree(MESH_CACHE_HOME, ignore_errors=True)

settings.register_profile('ci', derandomize=True, print_blob=True)
if os.environ.get('CI', '').lower() in ('1', 'true', 'yes'):
    settings.load_profile('ci')


def pytest_collection_modifyitems(session, config, items):
    """Files by their measured cost, costliest first (the module docstring); a stable sort,
    so each file's tests keep their order and stay together."""
    costs = json.loads(Path(__file__).with_name('file_costs.json').read_text())
    median = statistics.median(costs.values())
    items.sort(key=lambda item: -costs.get(item.nodeid.split('::')[0], median))
