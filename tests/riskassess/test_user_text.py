"""User text (case, body, joint and location names, descriptions) is shown literally: never read as
terminal markup, HTML or matplotlib math text (issue 20, item 10)."""
import json

import markupsafe
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from riskassess.cli import main  # noqa: E402
from riskassess.products.plotting import plain  # noqa: E402
from tests.riskassess.conftest import shortened_case  # noqa: E402

#: Names that broke the tool: rich closing tag without opening (MarkupError after the run), a link,
#: an emoji code, unbalanced math text ("$x^{$": ParseException in the report), a leading underscore
#: (a hidden legend entry), HTML.
CASE_NAME = "x[/red] [link=https://example.com]click[/link] :warning: $x^{$"
BODY_NAME = "panel[/bold]$x^{$"
JOINT_NAME = "hinge $a$ [red]"
LOCATION_NAME = "_root[/] <b>bold</b>"
DESCRIPTION = "<script>alert('x')</script> $E = mc^2$ [bold]loud[/bold]"


@pytest.mark.parametrize("text", [CASE_NAME, BODY_NAME, JOINT_NAME, LOCATION_NAME, "a\\$b", "$$", "100 $"])
def test_plain_labels_draw_literally(text):
    fig, ax = plt.subplots()
    ax.plot([0, 1], label=plain(text))
    ax.set_title(plain(text))
    ax.legend()
    fig.canvas.draw()  # math text is parsed when drawn
    shown = ax.get_legend().get_texts()[0]
    assert shown.get_text().strip() == plain(text).strip()
    assert not shown._preprocess_math(shown.get_text())[1]   # not math text
    plt.close(fig)


def _hostile_case(tmp_path, names: bool):
    """envisat_small (0.3 s) with the hostile description, and with hostile names when ``names``."""
    text = shortened_case(0.3)
    replacements = {'name = "envisat_small"': f"name = {json.dumps(CASE_NAME)}",
                    '"solar_array"': json.dumps(BODY_NAME), '"solar_array_hinge"': json.dumps(JOINT_NAME),
                    '"solar_array_hinge_panel"': json.dumps(LOCATION_NAME)} if names else {}
    for old, new in replacements.items():
        assert old in text, old
        text = text.replace(old, new)
    text = text.replace(text.split("description = ", 1)[1].split("\n", 1)[0], json.dumps(DESCRIPTION), 1)
    case = tmp_path / "hostile.toml"
    case.write_text(text)
    return case


def test_hostile_names_are_refused_by_the_schema(tmp_path, capsys):
    """Names become folder names and table keys: the case checker allows letters, digits, '.', '_'
    and '-' only (docs/case-format.md), so markup never reaches a terminal as a name."""
    assert main(["assess", str(_hostile_case(tmp_path, names=True)), "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    for key in ("name:", "target.bodies", "target.joints", "structures.weak_locations"):
        assert key in err, key
    assert not (tmp_path / "run").exists()


def test_a_hostile_description_runs_through_run_report_literally(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["assess", str(_hostile_case(tmp_path, names=False)), "--out", str(out), "--report"]) in (0, 6)
    page = (out / "report.html").read_text()
    assert str(markupsafe.escape(DESCRIPTION)) in page   # what Jinja2's autoescape makes of it
    assert "<script>alert" not in page
    assert (out / "report.pdf").stat().st_size > 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["status"] == "complete"
    assert manifest["products"] == ["report.html", "report.pdf", "capture.gif", "viewer.html"]
