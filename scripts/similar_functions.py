# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The pairs of functions in a package folder whose token sequences are alike: a copy kept in
two places (issue 38's measure: none in ``vib_estimator/core`` at 0.80 or above).

    .venv/bin/python scripts/similar_functions.py [FOLDER] [--min 0.80] [--tokens 40]

Each function and method (nested ones too) of the folder's ``*.py`` files, its docstring left
out, becomes its token sequence with every name (identifiers, attributes, built-ins) read as
``N``, every number as ``0`` and every string as ``S`` (keywords and operators kept), comments
and line breaks dropped; the similarity of two functions is ``difflib.SequenceMatcher``'s ratio
of their sequences (2 x matched tokens / both lengths). Functions shorter than ``--tokens``
tokens (properties, one-line wrappers) are left out. Prints a line per pair at or above
``--min``, most similar first: ``0.93  a.py:120 f  ~  b.py:40 g  (tokens 210 / 198)``; then
the count. Exit status 0 (a report, not a check).
"""

from __future__ import annotations

import argparse
import ast
import difflib
import io
import keyword
import sys
import tokenize
from pathlib import Path

DEFAULT_FOLDER = Path(__file__).resolve().parents[1] / 'vib_estimator' / 'core'
SKIP = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT}


def normalised_tokens(source: str) -> list[str]:
    """``source``'s tokens, names as ``N``, numbers as ``0``, strings as ``S``."""
    out = []
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type in SKIP or tok.type == tokenize.ENDMARKER:
            continue
        if tok.type == tokenize.NAME:
            out.append(tok.string if keyword.iskeyword(tok.string) else 'N')
        elif tok.type == tokenize.NUMBER:
            out.append('0')
        elif tok.type == tokenize.STRING or tok.type >= getattr(tokenize, 'FSTRING_START', 999):
            out.append('S')
        else:
            out.append(tok.string)
    return out


def functions(path: Path) -> list[tuple[str, int, str, list[str]]]:
    """(file, line, qualified name, tokens) of every function in ``path``, docstrings cut."""
    text = path.read_text()
    lines = text.splitlines(keepends=True)
    out = []

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                name = prefix + child.name
                body = child.body
                if (
                    body
                    and isinstance(body[0], ast.Expr)
                    and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)
                ):
                    body = body[1:]
                if body:
                    start, end = body[0].lineno - 1, child.end_lineno
                    src = ''.join(lines[start:end])
                    indent = len(src) - len(src.lstrip(' '))
                    src = ''.join(line[indent:] for line in lines[start:end])
                    try:
                        toks = normalised_tokens(src)
                    except (tokenize.TokenError, IndentationError):
                        toks = []
                    out.append((path.name, child.lineno, name, toks))
                visit(child, name + '.')
            elif isinstance(child, ast.ClassDef):
                visit(child, prefix + child.name + '.')

    visit(ast.parse(text), '')
    return out


def similar_pairs(folder: Path, threshold: float, min_tokens: int):
    """(ratio, a, b) of every pair of functions in ``folder`` at or above ``threshold``."""
    funcs = [
        f for p in sorted(folder.glob('*.py')) for f in functions(p) if len(f[3]) >= min_tokens
    ]
    pairs = []
    for i, a in enumerate(funcs):
        for b in funcs[i + 1 :]:
            la, lb = len(a[3]), len(b[3])
            if 2 * min(la, lb) / (la + lb) < threshold:
                continue
            m = difflib.SequenceMatcher(None, a[3], b[3], autojunk=False)
            if m.real_quick_ratio() >= threshold and m.quick_ratio() >= threshold:
                r = m.ratio()
                if r >= threshold:
                    pairs.append((r, a, b))
    pairs.sort(key=lambda p: -p[0])
    return pairs


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('folder', nargs='?', default=str(DEFAULT_FOLDER))
    parser.add_argument('--min', type=float, default=0.80, help='least similarity (0-1)')
    parser.add_argument('--tokens', type=int, default=40, help='fewest tokens a function has')
    args = parser.parse_args(argv)
    folder = Path(args.folder)
    if not folder.is_dir():
        print(f'error: {folder} is not a folder', file=sys.stderr)
        return 2
    pairs = similar_pairs(folder, args.min, args.tokens)
    for r, a, b in pairs:
        print(
            f'{r:.2f}  {a[0]}:{a[1]} {a[2]}  ~  {b[0]}:{b[1]} {b[2]}  '
            f'(tokens {len(a[3])} / {len(b[3])})'
        )
    print(f'{len(pairs)} pairs at >= {args.min:.2f} ({folder})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
