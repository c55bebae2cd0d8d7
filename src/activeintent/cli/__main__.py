"""``python -m activeintent.cli``."""

from activeintent.cli import app

app()
