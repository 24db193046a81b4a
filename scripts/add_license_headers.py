# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Put the licence header on every Python file of the repository that lacks it (idempotent).

    python scripts/add_license_headers.py          # add where missing
    python scripts/add_license_headers.py --check  # list the files without it, exit 1 if any

The header (:data:`HEADER`) goes first, after a ``#!`` line if there is one. ``make test`` checks
it (``test/test_lint.py``).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HEADER = '# Copyright 2026 vib_estimator developers\n# SPDX-License-Identifier: Apache-2.0\n'


def python_files():
    """The tracked and the untracked (not ignored) ``.py`` files of the repository."""
    out = subprocess.run(
        ['git', '-C', str(ROOT), 'ls-files', '--cached', '--others', '--exclude-standard', '*.py'],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return [ROOT / line for line in out.splitlines() if (ROOT / line).is_file()]


def has_header(text: str) -> bool:
    body = text.split('\n', 1)[1] if text.startswith('#!') else text
    return body.startswith(HEADER)


def add_header(text: str) -> str:
    if text.startswith('#!'):
        first, rest = text.split('\n', 1)
        return first + '\n' + HEADER + rest
    return HEADER + text


def main(argv=None) -> int:
    check = '--check' in (argv if argv is not None else sys.argv[1:])
    missing = [p for p in python_files() if not has_header(p.read_text())]
    if check:
        for p in missing:
            print(p.relative_to(ROOT))
        return 1 if missing else 0
    for p in missing:
        p.write_text(add_header(p.read_text()))
    print(f'{len(missing)} file(s) given the header')
    return 0


if __name__ == '__main__':
    sys.exit(main())
