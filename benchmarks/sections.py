"""A section of docs/benchmarks.md that a benchmark script owns, between its own markers."""

import os


def replace_section(path, text, begin, end):
    """Write ``text`` (which starts with ``begin`` and ends with ``end`` and a newline) into
    the file at ``path`` in place of the section between those markers, or at its end if the
    file has none (a missing file is created)."""
    old = open(path, encoding='utf-8').read() if os.path.exists(path) else ''
    if begin in old and end in old:
        new = old[:old.index(begin)] + text + old[old.index(end) + len(end) + 1:]
    else:
        new = old.rstrip('\n') + '\n\n' + text
    with open(path, 'w', encoding='utf-8') as out:
        out.write(new)
