"""Every ```python block of README.md runs as written (each in a fresh interpreter)."""

from pathlib import Path
import os
import re
import subprocess
import sys

import pytest

REPO = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r'^```python[ \t]*\n(.*?)^```[ \t]*$', re.MULTILINE | re.DOTALL)


def _blocks():
    text = (REPO / 'README.md').read_text(encoding='utf-8')
    return [(text.count('\n', 0, match.start()) + 1, match.group(1))
            for match in BLOCK.finditer(text)]


def test_readme_has_python_blocks():
    assert _blocks(), 'README.md has no ```python block'


@pytest.mark.parametrize('line, code', _blocks(), ids=lambda x: f'line{x}' if isinstance(x, int)
                         else '')
def test_readme_python_block_runs(tmp_path, line, code):
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='95',
               MPLBACKEND='Agg', PYTHONPATH=str(REPO))
    result = subprocess.run([sys.executable, '-c', code], cwd=tmp_path, capture_output=True,
                            text=True, timeout=300, env=env)
    assert result.returncode == 0, (f'README.md line {line}:\n{code}\n'
                                    f'stderr:\n{result.stderr[-3000:]}')
