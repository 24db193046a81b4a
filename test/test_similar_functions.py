# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""scripts/similar_functions.py: pairs of functions alike but for names and numbers."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location('similar', ROOT / 'scripts/similar_functions.py')
similar = importlib.util.module_from_spec(spec)
spec.loader.exec_module(similar)

ORIGINAL = '''
def energy(x, scale=2.0):
    """The docstring is left out."""
    total = 0.0
    for k, v in enumerate(x):
        if v > 0:
            total += scale * v * v + k
        else:
            total -= v
    return total / max(len(x), 1)
'''
#: the same function with other names, numbers and docstring
RENAMED = (
    ORIGINAL.replace('energy', 'power')
    .replace('scale', 'gain')
    .replace('total', 'acc')
    .replace('2.0', '3.5')
    .replace('1)', '7)')
    .replace('The docstring is left out.', 'Another, longer docstring, which must not count.')
)
OTHER = """
def unrelated(path):
    with open(path) as f:
        lines = [line.strip() for line in f if line and not line.startswith('#')]
    return {name: value for name, value in (line.split('=', 1) for line in lines)}
"""


def test_a_renamed_copy_is_found_and_a_different_function_is_not(tmp_path, capsys):
    (tmp_path / 'a.py').write_text(ORIGINAL + OTHER)
    (tmp_path / 'b.py').write_text(RENAMED)
    pairs = similar.similar_pairs(tmp_path, 0.8, 20)
    assert [(p[1][2], p[2][2]) for p in pairs] == [('energy', 'power')]
    assert pairs[0][0] == 1.0
    assert similar.main([str(tmp_path)]) == 0
    assert '1.00  a.py:2 energy  ~  b.py:2 power' in capsys.readouterr().out
    # a changed operator and an added statement lower the ratio below 1
    (tmp_path / 'b.py').write_text(RENAMED.replace('acc -= v', 'acc *= v\n            acc += 1'))
    assert 0.8 <= similar.similar_pairs(tmp_path, 0.8, 20)[0][0] < 1.0
    assert similar.similar_pairs(tmp_path, 0.99, 20) == []
