"""Pure-rolling bevel gears with a preset parabolic transmission error ([Preset-TE-bevel])."""
