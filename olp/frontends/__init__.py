"""Frontends: read a robot program (KUKA KRL, CSV, Python) and lower it to an ``ir.Program``."""
