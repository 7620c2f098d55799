"""The ``mtdagger`` LeRobot policy: per-input encoders + learned task embedding -> MLP head."""

from lerobot_mtdagger.policies.mtdagger.configuration_mtdagger import MTDAggerConfig
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import MTDAggerPolicy
from lerobot_mtdagger.policies.mtdagger.processor_mtdagger import make_mtdagger_pre_post_processors

__all__ = ["MTDAggerConfig", "MTDAggerPolicy", "make_mtdagger_pre_post_processors"]
