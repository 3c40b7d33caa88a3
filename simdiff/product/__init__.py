"""Everyday generation on top of the model code: validated requests, the pipeline behind
``simdiff generate`` (text → features → joints → files) and its output writers.

Modules: ``request`` (options → a checked :class:`~simdiff.product.request.GenerationRequest`,
no torch import), ``pipeline`` (sampling with timings), ``outputs`` (npy, BVH, video, metadata;
all written atomically through :mod:`simdiff.fsio`).
"""
