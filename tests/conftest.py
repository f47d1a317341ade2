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
"""

import gc
import os
import shutil
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
