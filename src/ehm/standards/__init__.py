"""Numerical leaves after published standards and models: reference curves, bands and findings
with their sources (``references``), transfer-function estimates (``transfer``), ISO 2631-1 weightings and
values and the ISO 2631-5 spinal dose (``comfort``), and the motion sickness model (``sickness``).  Pure
array functions: they import only ``ehm.errors``, never the model."""
