"""Base class for config models: strict (unknown keys are errors), immutable, JSON-friendly."""

from pydantic import BaseModel, ConfigDict


class StageConfig(BaseModel):
    """A stage's thresholds. Unknown keys are rejected so a typo in a config file is an error."""

    model_config = ConfigDict(extra="forbid", frozen=True)
