"""The symbolic core: from a generating function p(φ) to every derived quantity (Sections 2–3), exactly."""
