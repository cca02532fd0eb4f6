"""The string shooter's loop (placeholder under construction)."""
def shooter_figures(model, t, x):
    return {}
