"""Robot kinematics: closed-form OPW (:mod:`olp.kinematics.opw`) and a pinocchio chain
(:mod:`olp.kinematics.pinocchio_model`, imported on demand because pinocchio is heavy)."""
