"""PyBullet tabletop: robot, assets, skills, trajectory log τ, rendering, video export."""
