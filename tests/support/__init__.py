"""Helpers for the tests (warp kernels must live in real .py files)."""
