"""The user's YAML spec: Pydantic models, loading with ``extends``, drafting from files."""
