# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Offline studies and commands: analyze, reproduce, compare, baselines, Cramer-Rao bounds."""
