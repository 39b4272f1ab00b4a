"""Collision geometry and checking: a station as a pinocchio ``GeometryModel`` of coal shapes
(:mod:`olp.collision.scene`, :mod:`olp.collision.shapes`) and the conservative advancement that
proves a joint path free between its samples (:mod:`olp.collision.advance`). The pass over a
compiled program is :mod:`olp.passes.collide`.

Nothing here imports pinocchio, coal or trimesh at import time.
"""
