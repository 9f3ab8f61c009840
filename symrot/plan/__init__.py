"""The evaluation plan: how each coefficient is evaluated safely in each precision.

The layer between the symbolic core (:mod:`symrot.core`) and the backends (:mod:`symrot.backends`).
"""
