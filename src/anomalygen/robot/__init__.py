"""The robot: one agent class (:class:`~anomalygen.robot.agent.Agent`) that owns the model, the element
names, the control modes, the grab rule, the reach envelope and the action mapping; and the motion
layer every skill runs on (IK, OMPL paths, the :class:`~anomalygen.robot.driver.Driver`'s control loop)."""
