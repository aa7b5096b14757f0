"""Build the report of a run folder and write it as one self-contained HTML file and as PDF.

Both come from one Jinja2 template (``templates/report.html.j2``); the PDF is that HTML
rendered by WeasyPrint with the print rules of ``templates/report.css``.

A section is a function ``section(run: RunFolder) -> Section | None``, listed in
:data:`SECTIONS` in reading order. It returns ``None`` when its stage did not run (a
perception, towing, diagnosis or sweep section when the run folder holds none of its
results), and raises :class:`~riskassess.products.results.MissingData` when the folder lacks what
it needs: the report then shows the section with what is missing instead of failing.
Adding a stage's section is adding one module and one line here.
"""
from __future__ import annotations

import matplotlib

import datetime
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import jinja2

from riskassess.products import results
from riskassess.products.outfolder import claim_product
from riskassess.products.report.approach import approach_section
from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.report.capture import capture_section, net_integrity_section
from riskassess.products.report.diagnosis import diagnosis_section
from riskassess.products.report.impact import contact_section, debris_motion_section, energy_section, hinge_section
from riskassess.products.report.inputs import appendix_inputs_section, case_section, run_facts_section
from riskassess.products.report.perception import perception_section
from riskassess.products.plotting import STYLE
from riskassess.products.report.structures import joint_loads_section, stresses_section, verdict_section
from riskassess.products.report.towing import towing_section
from riskassess.products.results import MissingData, RunFolder
from riskassess.products.view.products import ViewFiles, write_views

#: (section id, title, builder) in reading order: the verdict first.
SECTIONS = (
    ("verdict", "Verdict: secondary debris", verdict_section),
    ("capture", "The capture in 3-D", capture_section),
    ("case", "Case summary: inputs", case_section),
    ("contact", "Contact forces and moments", contact_section),
    ("net-integrity", "Net threads: tension and integrity", net_integrity_section),
    ("debris-motion", "Debris velocity and angular velocity", debris_motion_section),
    ("hinges", "Hinge angles", hinge_section),
    ("joint-loads", "Hinge and joint loads against allowables", joint_loads_section),
    ("stresses", "Stresses against strengths", stresses_section),
    ("energy", "Net and debris energy", energy_section),
    ("perception", "Perception: debris mass and inertia", perception_section),
    ("diagnosis", "Model diagnosis against measured data", diagnosis_section),
    ("towing", "Towing: main tether and tethered bodies", towing_section),
    ("approach", "Net approach with maneuverable units", approach_section),
    ("run-facts", "Run facts", run_facts_section),
    ("appendix-inputs", "Appendix: every case input", appendix_inputs_section),
)
TEMPLATES = Path(__file__).parent / "templates"


@dataclass
class ReportOutput:
    html: Path
    pdf: Path | None
    pdf_pages: int | None
    section_pages: dict          # section id -> PDF page number (1-based) where it starts
    sections: list[Section]
    views: ViewFiles | None = None   # capture.gif and viewer.html (None: the folder has no net to show)


def tool_version() -> str:
    try:
        return version("adr-riskassess")
    except PackageNotFoundError:
        return "unknown"


def build_sections(run: RunFolder, progress=None) -> list[Section]:
    """Every applicable section; a section whose data is missing says what is missing.

    Parameters
    ----------
    run : RunFolder
        The output folder the report is made of.
    progress : callable, optional
        ``progress(sections done, sections, title of the next)``.

    Returns
    -------
    list of Section
    """
    sections = []
    for k, (section_id, title, build) in enumerate(SECTIONS):
        if progress:
            progress(k, len(SECTIONS), title)
        try:
            with matplotlib.rc_context(STYLE):
                section = build(run)
        except MissingData as exc:
            # a folder of another stage (approach, tow) has no impact results to miss
            section = Section(section_id, title, missing=str(exc)) if run.stage == "impact" else None
        if section is not None:
            sections.append(section)
    if progress:
        progress(len(SECTIONS), len(SECTIONS), "done")
    return sections


def folder_problems(run: RunFolder) -> list[str]:
    """What the report's head warns about: a run that did not complete, missing core files.

    Parameters
    ----------
    run : RunFolder
        The output folder the report is made of.

    Returns
    -------
    list of str
        One sentence per problem.
    """
    problems = []
    if not run.complete:
        problems.append(f"the run's status is '{run.manifest.get('status')}'"
                        + (f" ({run.manifest['error']})" if run.manifest.get("error") else "")
                        + "; sections without their data say what is missing.")
    missing = run.missing_core_files()
    if missing:
        problems.append(f"missing files: {', '.join(missing)}.")
    return problems


def render_html(run: RunFolder, sections: list[Section]) -> str:
    """The report of a run folder as one self-contained HTML document.

    Parameters
    ----------
    run : RunFolder
        The output folder the report is made of.
    sections : list of Section
        The sections, from :func:`build_sections`.

    Returns
    -------
    str
        The HTML text.
    """
    case_name = run.manifest.get("case", run.path.name)
    try:
        description = run.case.get("description") or ""
    except MissingData:
        description = ""
    return render_document(f"Net-capture risk report: {case_name}", description, run.path,
                           run.manifest.get("created", "-"), folder_problems(run), sections)


def render_document(title: str, subtitle: str, folder: Path, created: str, problems: list[str],
                    sections: list[Section]) -> str:
    """The report template filled with any list of sections (runs, sweeps, later stages).

    Parameters
    ----------
    title : str
        Document title.
    subtitle : str
        Line under the title (the case's description, the sweep's arguments).
    folder : Path
        The folder the report is written into, shown in the head.
    created : str
        When the results were made (ISO 8601 UTC).
    problems : list of str
        Warnings shown at the top.
    sections : list of Section
        The sections in reading order.

    Returns
    -------
    str
        The HTML text.
    """
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES), autoescape=True,
                             undefined=jinja2.StrictUndefined)
    env.tests.update(table=lambda b: isinstance(b, Table), figure=lambda b: isinstance(b, Figure),
                     note=lambda b: isinstance(b, Note))
    return env.get_template("report.html.j2").render(
        title=title, subtitle=subtitle, run_dir=str(folder), created=created,
        generated=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        tool_version=tool_version(), problems=problems, sections=sections,
        css=(TEMPLATES / "report.css").read_text())


def render_pdf(html: str, base_url: Path):
    """WeasyPrint document of the HTML: (pdf bytes, page count, section id -> first page).

    Parameters
    ----------
    html : str
        The report HTML (:func:`render_document`).
    base_url : Path
        Folder that relative links of the HTML resolve against.

    Returns
    -------
    pdf : bytes
    pages : int
    section_pages : dict of str to int
        Anchor id -> 1-based page where it first appears.
    """
    import weasyprint

    document = weasyprint.HTML(string=html, base_url=str(base_url)).render()
    section_pages = {}
    for number, page in enumerate(document.pages, start=1):
        for anchor in page.anchors:
            section_pages.setdefault(anchor, number)
    return document.write_pdf(), len(document.pages), section_pages


def write_report(run_dir: str | Path, pdf: bool = True, progress=None, views: bool = True) -> ReportOutput:
    """Write ``report.html`` (and ``report.pdf``) into the run folder, each atomically, and with
    ``views`` the animation and the viewer beside it (:func:`riskassess.products.view.products.write_views`);
    refused (:class:`riskassess.products.outfolder.OutputRefused`) where a file of that name is not the run's own.

    Parameters
    ----------
    run_dir : str or Path
        An output folder of this tool (``run``, ``assess``, ``perceive``, ``tow``, ``approach``,
        ``diagnose``).
    pdf : bool
        Also write ``report.pdf``.
    progress : callable, optional
        ``progress(sections done, sections, title of the next)``.
    views : bool
        Also write the animation and the interactive viewer when the folder has a capture to show.

    Returns
    -------
    ReportOutput
    """
    run = RunFolder(run_dir)
    for name in ("report.html", "report.pdf") if pdf else ("report.html",):
        claim_product(run.path, run.manifest, name)
    sections = build_sections(run, progress)
    html = render_html(run, sections)
    html_path = run.path / "report.html"
    results.atomic_write_bytes(html_path, html.encode("utf-8"))
    run.add_product("report.html")
    pdf_path, pages, section_pages = None, None, {}
    if pdf:
        data, pages, anchors = render_pdf(html, run.path)
        section_pages = {s.id: anchors[s.id] for s in sections if s.id in anchors}
        pdf_path = run.path / "report.pdf"
        results.atomic_write_bytes(pdf_path, data)
        run.add_product("report.pdf")
    view_files = None
    if views and any(s.id == "capture" and not s.missing for s in sections):
        view_files = write_views(run)
    return ReportOutput(html_path, pdf_path, pages, section_pages, sections, view_files)
