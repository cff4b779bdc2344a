"""Tests of the evaluators and the evaluation cache."""
