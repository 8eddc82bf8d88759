"""The README is one screen a newcomer reads (issue 28, item 4): the two commands first,
a picture, a short tour, one table whose cells are numbers with links; every other
explanation on a page of docs/, each page it links there."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_the_two_commands_come_first():
    lines = README.splitlines()
    assert lines[2] == "```bash"
    assert lines[3].startswith("./do main    # set-up")
    assert lines[4].startswith("./do test    # set-up")


def test_the_readme_fits_one_screen():
    assert len(README.splitlines()) <= 45
    assert README.count("```python") == 0  # the API example lives in docs/api.md


def test_the_tour_has_the_five_steps():
    tour = re.findall(r"```bash\n(.*?)```", README, flags=re.S)[1]
    steps = [line.split()[0:2] for line in tour.strip().splitlines()]
    assert steps == [
        ["plannerlab", "solve"],
        ["plannerlab", "execute"],
        ["plannerlab", "view"],
        ["plannerlab", "compare"],
        ["./do", "jupyter"],
    ]


def test_the_results_cells_are_numbers_with_links_and_commits():
    rows = [r for r in README.splitlines() if r.startswith("| ") and "---" not in r][1:]
    assert rows
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert re.search(r"\(`[0-9a-f]{7}`\)", cells[0]), cells[0]  # measured at a commit
        for cell in cells[1:]:
            assert cell == "–" or re.match(r"^\[\d[\d/ .,]*\]\(results/[\w/]+\.md\)", cell), cell
            assert len(cell.split()) <= 12, cell


def test_every_link_of_the_readme_and_docs_resolves():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text("utf-8")):
            if target.startswith(("http://", "https://")):
                continue
            if not (page.parent / target).exists():
                broken.append(f"{page.relative_to(ROOT)}: {target}")
    assert broken == []
