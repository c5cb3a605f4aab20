"""Simulated recordings with ground truth (placeholder, filled below)."""
from .kinematics import *  # noqa
from .sensor import *  # noqa
