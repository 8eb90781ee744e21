"""What the user sees: scene properties, preferences, panels that only draw, and thin operators."""
