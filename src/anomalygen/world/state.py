"""A simulator state saved to a file and put back: how a run's final state reaches the referee.

Why a file: the robot's items end when the robot does; judging comes afterwards, in another stage
and process, and must see exactly the state the robot left (what it still holds included). The whole
integration state is kept (positions, velocities, actuator inputs, mocap targets, which welds are
on), so restoring it into the same scene's model reproduces that instant.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

_WHICH = "mjSTATE_INTEGRATION"


def get_state(model, data) -> np.ndarray:
    """``data``'s whole integration state as one vector."""
    import mujoco

    which = getattr(mujoco.mjtState, _WHICH)
    state = np.empty(mujoco.mj_stateSize(model, which))
    mujoco.mj_getState(model, data, state, which)
    return state


def set_state(model, data, state: np.ndarray) -> None:
    """Put a :func:`get_state` vector into ``data`` (of a model of the same scene) and run mj_forward."""
    import mujoco

    which = getattr(mujoco.mjtState, _WHICH)
    if state.size != mujoco.mj_stateSize(model, which):
        raise ValueError("the saved state does not fit this model")
    mujoco.mj_setState(model, data, state, which)
    mujoco.mj_forward(model, data)


def save_state(path: str | Path, model, data) -> None:
    """Write ``data``'s integration state (and, for people, qpos and qvel) atomically to ``path``."""
    from anomalygen.runfolder import atomic_write_bytes

    buf = io.BytesIO()
    np.savez_compressed(buf, state=get_state(model, data), qpos=np.asarray(data.qpos), qvel=np.asarray(data.qvel),
                        nq=model.nq, nv=model.nv)
    atomic_write_bytes(Path(path), buf.getvalue())


def restore_state(path: str | Path, model, data) -> None:
    """Put the state saved at ``path`` into ``data`` (of the same scene's model)."""
    with np.load(Path(path)) as saved:
        if int(saved["nq"]) != model.nq or int(saved["nv"]) != model.nv:
            raise ValueError(f"{path}: saved for another model ({int(saved['nq'])} positions, this one has {model.nq})")
        state = saved["state"]
    set_state(model, data, state)
