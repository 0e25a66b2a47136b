"""Batch work: libraries of recorded clips turned into simulated, balanced motion, on one machine or a Ray cluster."""
