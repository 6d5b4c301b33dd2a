"""The virtual LiMMS of chapter 10: a true motor simulated in more detail than the models
(LuGre presliding, cogging, encoder quantization, noise, a sampled controller) and the thesis'
experiments on it, run through the identification toolkit as if it were measured."""
from .motor import VirtualMotor, synthetic_cogging
from .sampled import DiscretePID, Record, run

__all__ = ["VirtualMotor", "synthetic_cogging", "DiscretePID", "Record", "run"]
