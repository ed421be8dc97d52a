"""Rack-generated involute spur and helical gears."""
