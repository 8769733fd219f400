"""Where MuJoCo's messages go: its warnings to the `ecs_tentacles.mujoco` logger, never to
MUJOCO_LOG.TXT in the working folder (process-wide, set when a physics backend is made)."""

from __future__ import annotations

import logging

import mujoco

log = logging.getLogger("ecs_tentacles.mujoco")


def _log_mujoco_warning(message: str) -> None:
    log.warning("%s", message.strip())


def route_mujoco_messages() -> None:
    """Send MuJoCo's warnings to `logging`, never to MUJOCO_LOG.TXT in the working folder."""
    mujoco.set_mju_user_warning(_log_mujoco_warning)
