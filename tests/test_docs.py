"""The docs are true: every Python block of README.md and docs/ runs as written, and every
relative link (with its #anchor) leads somewhere."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
        ROOT / "benchmarks" / "README.md"]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def python_blocks(path: Path) -> list[str]:
    return BLOCK.findall(path.read_text(encoding="utf-8"))


def anchors(path: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"^```.*?^```", "", path.read_text(encoding="utf-8"), flags=re.S | re.M)
    headings = re.findall(r"^#+\s+(.*?)\s*$", text, re.M)
    return {re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-") for h in headings}


@pytest.mark.parametrize("path", [p for p in DOCS if python_blocks(p)],
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_python_blocks_run_as_written(path, tmp_path, monkeypatch):
    # the blocks of one file run in order in one namespace, from a fresh folder that has
    # the repository's meshes/ and examples/ (the paths the docs use)
    for name in ("meshes", "examples"):
        (tmp_path / name).symlink_to(ROOT / name, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for i, block in enumerate(python_blocks(path)):
        code = compile(block, f"{path.name}, python block {i + 1}", "exec")
        exec(code, namespace)  # noqa: S102 - the repository's own documentation
    if path.name == "README.md":
        check_tour_outputs(tmp_path)


TOUR_OUTPUT = "out/tour"
"""The folder the README's tour declares for every file it writes."""
TOUR_FILES = {"mode1.png", "modes.vtu", "modes.pvd", "modes_steps", "frame_se.npz"}
"""What the tour says it writes there."""


def check_tour_outputs(folder: Path) -> None:
    """The tour wrote its files into TOUR_OUTPUT and nothing anywhere else below ``folder``
    (the working folder it ran from, holding only the links to meshes/ and examples/)."""
    rel = [p.relative_to(folder) for p in folder.rglob("*")]
    outside = sorted(r.as_posix() for r in rel if r.parts[0] not in ("meshes", "examples")
                     and r != Path("out") and not r.is_relative_to(TOUR_OUTPUT))
    assert not outside, f"the README's tour wrote {outside} outside {TOUR_OUTPUT}/"
    written = {p.name for p in (folder / TOUR_OUTPUT).iterdir()}
    assert written == TOUR_FILES, written
    assert any((folder / TOUR_OUTPUT / "modes_steps").iterdir())


def test_readme_declares_the_tour_output_folder():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    tour = text.split("## A tour of the API", 1)[1].split("\n## ", 1)[0]
    assert f"`{TOUR_OUTPUT}/`" in tour
    assert f'Path("{TOUR_OUTPUT}")' in tour
    for name in TOUR_FILES:  # each output is named where the outputs are described
        assert name in tour, name
    assert "`modes_steps/`" in text.split("## A tour of the API", 1)[0]  # the quick start


def test_every_relative_link_resolves():
    broken, checked = [], 0
    for path in DOCS:
        for target in LINK.findall(path.read_text(encoding="utf-8")):
            if re.match(r"[a-z]+:", target):  # http(s), mailto: not checked offline
                continue
            checked += 1
            file, _, anchor = target.partition("#")
            dest = (path.parent / file).resolve() if file else path
            if not dest.exists():
                broken.append(f"{path.name}: {target} (no file {dest})")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{path.name}: {target} (no heading #{anchor})")
    assert checked >= 5  # the docs do link to each other
    assert not broken, broken


HISTORY = re.compile(r"\bissue\s*\d+|the issue|--suite issue", re.I)
"""Development history that user docs do not carry: issue numbers, "the issue's ...",
the benchmark suites' old names."""


@pytest.mark.parametrize("path", [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))],
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_user_docs_carry_no_development_history(path):
    found = [f"{path.name}:{n}: {m.group(0)!r}"
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             for m in HISTORY.finditer(line)]
    assert not found, found


def test_benchmark_docs_use_the_current_suite_names():
    text = (ROOT / "benchmarks" / "README.md").read_text(encoding="utf-8")
    assert "--suite issue" not in text
    assert "--suite components" in text
