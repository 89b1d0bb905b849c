"""Hand-driven mechanics (placeholder during development)."""
