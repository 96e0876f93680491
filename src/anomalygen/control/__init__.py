"""Robot control: the simulation driver, motion primitives, IK and motion planning."""
