# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The README and docs/ are a tree a reader can navigate: every relative link reaches a file, and
every ``#anchor`` a heading of it (GitHub's slugs); every docs page is linked from the README."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / 'README.md', *sorted((ROOT / 'docs').glob('*.md'))]
LINK = re.compile(r'\[[^\]]*\]\(([^)\s]+)\)')
FENCE = re.compile(r'^```.*?^```', re.S | re.M)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r'[^\w\- ]', '', heading.strip().lower())
    return text.replace(' ', '-')


def anchors(page: Path) -> set:
    text = FENCE.sub('', page.read_text())
    return {slug(m.group(2)) for m in re.finditer(r'^(#+) (.+)$', text, re.M)}


def links(page: Path):
    text = FENCE.sub('', page.read_text())
    text = re.sub(r'`[^`]*`', '', text)
    return [m.group(1) for m in LINK.finditer(text)]


def test_every_relative_link_and_anchor_resolves():
    broken = []
    for page in PAGES:
        for target in links(page):
            if re.match(r'^[a-z]+:', target):
                continue  # http(s), mailto: not checked here
            path, _, anchor = target.partition('#')
            dest = (page.parent / path).resolve() if path else page
            if not dest.exists():
                broken.append(f'{page.name}: {target} (no file)')
            elif anchor and dest.suffix == '.md' and anchor not in anchors(dest):
                broken.append(f'{page.name}: {target} (no heading)')
    assert not broken, '\n'.join(broken)


def test_every_docs_page_is_linked_from_the_readme():
    linked = {(ROOT / t.partition('#')[0]).resolve() for t in links(ROOT / 'README.md')}
    orphans = [p.name for p in PAGES[1:] if p.resolve() not in linked]
    assert not orphans, orphans
