"""Pieces shared by tasks and constraints (activation life cycle)."""
from .task_base import ActivationState, TaskBase

__all__ = ["ActivationState", "TaskBase"]
