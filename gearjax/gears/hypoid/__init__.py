"""Face-milled spiral-bevel and hypoid gears."""
