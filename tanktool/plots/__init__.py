"""matplotlib figures; each module imports matplotlib lazily (Agg when headless)."""
