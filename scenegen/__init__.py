"""scenegen."""
