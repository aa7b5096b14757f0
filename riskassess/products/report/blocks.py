"""What a report section is made of: tables, figures, notes. Plain data the template renders."""
from __future__ import annotations

import base64
from dataclasses import dataclass, field
from riskassess.products.plotting import png_bytes

#: Resolution of embedded figures (dots per inch): sharp on screen and in print at 17 cm width.
FIGURE_DPI = 150


@dataclass
class Table:
    columns: list[str]
    rows: list[list[str]]
    caption: str = ""
    #: Row indices to highlight as failing (verdict rows).
    alarm_rows: set = field(default_factory=set)
    css_class: str = ""


@dataclass
class Figure:
    id: str            # stable HTML id, e.g. 'fig-contact'
    caption: str
    png_base64: str    # the image, embedded so the report opens offline

    @classmethod
    def from_matplotlib(cls, id: str, caption: str, fig) -> Figure:
        """Render and close a matplotlib figure.

        Parameters
        ----------
        id : str
            Stable HTML id, e.g. ``"fig-contact"``.
        caption : str
            Caption under the figure.
        fig : matplotlib.figure.Figure
            The figure, rendered at :data:`FIGURE_DPI`.
        """
        return cls(id, caption, base64.b64encode(png_bytes(fig, FIGURE_DPI)).decode("ascii"))


@dataclass
class Note:
    text: str
    kind: str = "info"   # 'info', 'warning' (something is missing or approximate), 'alarm' (a failure)


@dataclass
class Section:
    id: str            # HTML anchor, e.g. 'verdict'
    title: str
    blocks: list = field(default_factory=list)
    #: Set when the run folder lacks what the section needs; the section then says so.
    missing: str | None = None

    @property
    def figures(self) -> list[Figure]:
        return [b for b in self.blocks if isinstance(b, Figure)]
