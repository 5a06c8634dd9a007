"""Live traffic display (FastAPI + WebSocket + static page)."""
