"""The Sun's position and the camera's angle to it (Lee 2017, 4.1.1), for the Sun-compensated
colour model (Lee 2017, 4.3)."""

__all__: list[str] = []
