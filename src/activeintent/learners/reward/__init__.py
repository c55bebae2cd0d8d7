"""Reward learning over state features (APReL-style): ``reward-preference``, ``reward-stop``."""
