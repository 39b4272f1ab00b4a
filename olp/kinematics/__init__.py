"""Robot kinematics behind one interface (:mod:`olp.kinematics.base`): closed-form OPW
(:mod:`olp.kinematics.opw`), closed-form Universal Robots (:mod:`olp.kinematics.ur`), and any
chain held as a pinocchio model with numeric IK (:mod:`olp.kinematics.numeric`); the adapters
are in :mod:`olp.kinematics.models`. pinocchio is heavy, so :mod:`olp.kinematics.pinocchio_model`
and :mod:`olp.kinematics.numeric` are imported only on demand."""
