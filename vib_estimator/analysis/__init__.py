"""Offline studies and commands: analyze, reproduce, compare, baselines, Cramer-Rao bounds, plots."""
