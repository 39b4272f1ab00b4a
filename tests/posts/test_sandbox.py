"""Posts run no code: bare post names never resolve to folders of the working directory, and
templates render in a sandbox that calls nothing but macros, Jinja helpers and plain-data
methods, and refuses expressions that could start a new line (issue 10, items 2 and 5)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import olp
from olp.errors import PostError, UsageError
from olp.posts import find_post

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
MILLING = REPO / "examples" / "milling.src"
BUNDLED_KUKA = REPO / "posts" / "kuka"


def _hostile_copy(folder: Path, line: str) -> Path:
    """A copy of the bundled KUKA post whose program template carries ``line`` after DEF."""
    shutil.copytree(BUNDLED_KUKA, folder)
    template = folder / "program.src.j2"
    text = template.read_text(encoding="utf-8")
    template.write_text(
        text.replace("DEF {{ program.name }}( )\n", f"DEF {{{{ program.name }}}}( )\n{line}\n")
    )
    return folder


def test_a_folder_named_like_a_bundled_post_does_not_replace_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _hostile_copy(tmp_path / "kuka", "; HIJACKED")
    monkeypatch.chdir(tmp_path)
    post = find_post("kuka")
    assert post.manifest.folder.resolve() == BUNDLED_KUKA.resolve()
    result = olp.build(olp.load_station(CELL), MILLING, post="kuka")
    assert "HIJACKED" not in result.files["Milling.src"]


def test_a_bare_name_that_is_only_a_local_folder_is_refused_with_a_hint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _hostile_copy(tmp_path / "kuka_line3", "; LINE 3")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UsageError) as err:
        find_post("kuka_line3")
    assert "./kuka_line3" in err.value.format()


def test_a_folder_post_named_as_a_path_is_used(tmp_path: Path) -> None:
    folder = _hostile_copy(tmp_path / "kuka_line3", "; LINE 3")
    result = olp.build(olp.load_station(CELL), MILLING, post=str(folder))
    assert "; LINE 3\r\n" in result.files["Milling.src"]


def test_a_path_without_post_yaml_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r"no post\.yaml"):
        find_post(str(tmp_path / "nothing"))


ESCAPES = {
    "numpy method writes a file": "{{ steps[0].joints.tofile('PWNED') }}",
    "station method": "{{ station.robot.flange_poses(steps[0].joints) }}",
    "template globals": "{{ self._TemplateReference__context.cycler.__init__.__globals__ }}",
    "class hierarchy": "{{ ''.__class__.__mro__[1].__subclasses__() }}",
    "lipsum globals": "{{ lipsum.__globals__['os'].popen('id').read() }}",
    "path method": "{{ post.__class__ }}",
    "mutating a list": "{% set x = [] %}{{ x.append(1) }}",
}


@pytest.mark.parametrize("line", ESCAPES.values(), ids=list(ESCAPES))
def test_templates_cannot_run_code(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, line: str
) -> None:
    folder = _hostile_copy(tmp_path / "evil", line)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(PostError, match=r"unsafe|may not call"):
        olp.build(olp.load_station(CELL), MILLING, post=str(folder), out_dir=tmp_path / "out")
    assert not (tmp_path / "PWNED").exists()
    assert not (tmp_path / "out").exists()


def test_a_bare_float_in_a_template_is_refused(tmp_path: Path) -> None:
    folder = _hostile_copy(tmp_path / "floaty", "; {{ steps[0].instruction.speed.linear }}")
    with pytest.raises(PostError, match="bare number"):
        olp.build(olp.load_station(CELL), MILLING, post=str(folder))


def test_an_expression_with_a_line_break_is_refused(tmp_path: Path) -> None:
    folder = _hostile_copy(tmp_path / "newline", "; {{ 'a\\nLIN {X 0,Y 0,Z 0}' }}")
    with pytest.raises(PostError, match="control character"):
        olp.build(olp.load_station(CELL), MILLING, post=str(folder))


def test_macros_and_loop_helpers_still_work(tmp_path: Path) -> None:
    line = (
        "{% macro twice(x) %}{{ x }}{{ x }}{% endmacro %}"
        "; {{ twice('ab') }} {{ {'k': 1}.items() | list | length }} {{ 'x'.upper() }}"
    )
    folder = _hostile_copy(tmp_path / "fine", line)
    result = olp.build(olp.load_station(CELL), MILLING, post=str(folder))
    assert "; abab 1 X\r\n" in result.files["Milling.src"]
