"""Jinja2 templates of the symrot backends (shipped inside the wheel as symrot.backends.templates)."""
