"""VH-CATT cylindrical gears (variable hyperbolic circular-arc tooth trace), [VH-CATT]."""
