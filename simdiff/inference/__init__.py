"""Inference: the shipped model and its sampling defaults (:mod:`.default`, no torch until a model loads) and
the text-to-motion generator (:mod:`.generator`)."""
