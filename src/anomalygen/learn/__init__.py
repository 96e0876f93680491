"""learn stage: execute each plan with primitives, SAC or CEM and check success."""
