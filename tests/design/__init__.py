"""Tests of the design search."""
