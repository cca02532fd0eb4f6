"""The scene: its schema (frozen dataclasses whose field metadata say what each TOML key may hold), the
strict loader with ``--set`` overrides, and the writer of resolved scene files."""
