"""Looking at a converted scene: a self-contained HTML viewer/report with a slider per joint."""

from ..stage import StageSpec
from .html import build_viewer_html, write_report
from .payload import scene_payload

STAGE_VERSION = "1"
STAGE = StageSpec("viewer", __name__, STAGE_VERSION, sections=(), upstream=("export",))

__all__ = ["STAGE", "STAGE_VERSION", "build_viewer_html", "scene_payload", "write_report"]
