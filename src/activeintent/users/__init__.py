"""Users who give the sparse signal h: simulated users with a hidden intention (and humans via the web app)."""
