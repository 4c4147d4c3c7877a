"""Every user string reaches report.html and the notebook summaries as text: escaped
exactly once (femmech.html.element), never as markup; links are relative paths only."""

from __future__ import annotations

from html.parser import HTMLParser

import pytest

from femmech.html import Markup, element, html_summary, text, url
from femmech.output.report import Figure, Section, Table, render_report, render_section
from femmech.scene.load import Scene
from femmech.scene.run import run_scene

IMG = "<img src=x onerror=alert(1)>"
SCRIPT = '"><script>alert(2)</script>'
AMP = "a &amp; b"  # must show as typed: escaped once, not decoded


class Page(HTMLParser):
    """Tags with their attributes, and the text, of an HTML page."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.text = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_startendtag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


def parse(page: str) -> Page:
    parser = Page()
    parser.feed(page)
    parser.close()
    return parser


def assert_inert(page: str) -> Page:
    """No script, no event handler, no foreign link in ``page``."""
    parsed = parse(page)
    assert [t for t, _ in parsed.tags if t == "script"] == []
    for tag, attrs in parsed.tags:
        assert not [a for a in attrs if a.startswith("on")], (tag, attrs)
        for key in ("href", "src"):
            value = attrs.get(key) or ""
            assert ":" not in value, (tag, attrs)
            assert not value.startswith("/"), (tag, attrs)
    images = [a["src"] for t, a in parsed.tags if t == "img"]
    assert all(src.endswith(".png") for src in images), images
    return parsed


def evil_scene(tmp_path) -> Scene:
    group, node_set, part = f"posts {IMG}", f"feet {SCRIPT}", f"frame {IMG}"
    material = f"steel {SCRIPT}"
    data = {
        "scene": {"name": f"press {IMG}", "description": f"{SCRIPT} {AMP}"},
        "materials": {material: {"E": "210 GPa", "nu": 0.3, "rho": "7850 kg/m^3"}},
        "parts": {part: {
            "generator": {"kind": "members",
                          "joints": {"a": [0, 0, 0], "b": [0, 0, 1.0], "c": [1.0, 0, 1.0],
                                     "d": [1.0, 0, 0]},
                          "members": [{"group": group, "chain": ["a", "b", "c", "d"],
                                       "divisions": 4}],
                          "node_sets": {node_set: ["a", "d"]}},
            "sections": {group: {"section": "circle", "diameter": "40 mm",
                                 "material": material}},
            "supports": [{"nodes": node_set}],
            "masses": [{"node": "b", "mass": "5 kg"}],
        }},
        "analyses": {"modes": {"n_modes": 3, "images": 1, "vtu": False}},
    }
    return Scene.from_dict(data, tmp_path, f"scene {IMG}.toml")


def test_user_strings_of_a_scene_reach_the_report_as_text(tmp_path):
    result = run_scene(evil_scene(tmp_path), tmp_path / "out", cache_dir=None)
    page = result.report.read_text(encoding="utf-8")
    parsed = assert_inert(page)
    assert [a["src"] for t, a in parsed.tags if t == "img"] == ["mode_01.png"]
    shown = "".join(parsed.text)
    # the parsed text is what the user wrote: escaped once (not twice, not decoded)
    for typed in (f"press {IMG}", f"{SCRIPT} {AMP}", f"frame {IMG}", f"posts {IMG}",
                  f"steel {SCRIPT}", f"feet {SCRIPT}"):
        assert typed in shown, typed
    assert "&lt;img src=x onerror=alert(1)&gt;" in page
    assert "&quot;&gt;&lt;script&gt;" in page
    assert "a &amp;amp; b" in page


def test_report_parts_escape_every_string_and_attribute():
    section = Section(IMG, (SCRIPT,), (Table(IMG, (SCRIPT,), ((IMG,),), note=SCRIPT),),
                      (Figure("mode_01.png", f'x" onerror="alert(3) {IMG}'),),
                      ("data.csv",), warnings=(IMG,), preformatted=(SCRIPT,))
    page = render_report(IMG, SCRIPT, [section], [IMG])
    parsed = assert_inert(page)
    alts = [a["alt"] for t, a in parsed.tags if t == "img"]
    assert alts == [f'x" onerror="alert(3) {IMG}']
    assert "".join(parsed.text).count(IMG) >= 6


@pytest.mark.parametrize("target", ["javascript:alert(1)", " JavaScript:alert(1)",
                                    "data:text/html,<script>", "http://example.com/x.png",
                                    "//example.com/x.png", "/etc/passwd", "a\\b.png"])
def test_links_must_be_relative_paths(target):
    with pytest.raises(ValueError, match="expected a relative path inside the report"):
        url(target)
    with pytest.raises(ValueError, match="link target"):
        render_section(Section("s", files=(target,)), "s1")
    with pytest.raises(ValueError, match="link target"):
        render_section(Section("s", figures=(Figure(target, "c"),)), "s1")


def test_element_escapes_text_and_attributes_once_and_keeps_markup():
    assert url("modes_steps/step 1.vtu") == "modes_steps/step%201.vtu"
    assert url("#s2") == "#s2"
    cell = element("td", "1 < 2 & 3", class_='num" onclick="x')
    assert cell == '<td class="num&quot; onclick=&quot;x">1 &lt; 2 &amp; 3</td>'
    assert element("p", text("<b>")) == "<p>&lt;b&gt;</p>"  # not escaped twice
    assert element("p", Markup("&#9888; "), "x") == "<p>&#9888; x</p>"
    with pytest.raises(ValueError, match="no children"):
        element("img", "child", src="a.png")
    with pytest.raises(ValueError, match="attribute"):
        element("p", "x", **{'a" b': "1"})


def test_notebook_summary_escapes_its_strings():
    page = html_summary(IMG, [(SCRIPT, IMG)], (IMG,), [(SCRIPT,)], note=IMG)
    parsed = assert_inert(page)
    assert "".join(parsed.text).count(IMG) == 4  # title, fact, header, note
