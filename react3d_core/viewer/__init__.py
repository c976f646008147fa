"""Looking at a converted scene: the self-contained viewer page with a slider per joint (``page``), and
``report.html``, that page with the parts, metrics and timings (``report``)."""

from ..stage import StageSpec
from .page import build_viewer_html
from .payload import scene_payload
from .report import write_report

STAGE_VERSION = "1"
STAGE = StageSpec("viewer", __name__, STAGE_VERSION, sections=(), upstream=("export",))

__all__ = ["STAGE", "STAGE_VERSION", "build_viewer_html", "scene_payload", "write_report"]
