"""Actuator models of every fidelity and what they return (:class:`Response`)."""

from pneumorph.models.response import ActuatorModel, Response

__all__ = ["ActuatorModel", "Response"]
