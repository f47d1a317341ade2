"""Shared by the tests of the package's commands: what setup.py declares."""

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def console_scripts():
    """The console scripts that setup.py declares (name -> 'module:function')."""
    tree = ast.parse((REPO / 'setup.py').read_text(encoding='utf-8'))
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts':
                    return dict(item.split(' = ') for item in ast.literal_eval(value))
    raise AssertionError('setup.py declares no console_scripts')
