"""Envs: where a plan y becomes a trajectory τ (Gymnasium-style: small API, a registry).

``symbolic`` predicts τ with the symbolic world model (fast, no images); ``pybullet`` runs
real physics with a Panda arm and can render frames. Add your own with
``ENVS.register("name", factory)``.
"""

from activeintent.envs.base import ENVS, Env, make_env

__all__ = ["ENVS", "Env", "make_env"]
