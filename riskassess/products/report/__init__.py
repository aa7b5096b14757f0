"""HTML/PDF risk reports of a run folder (``riskassess report RUN_DIR``); see :mod:`.document`."""
from riskassess.products.report.document import SECTIONS, ReportOutput, build_sections, write_report

__all__ = ["SECTIONS", "ReportOutput", "build_sections", "write_report"]
