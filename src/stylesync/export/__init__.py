"""Session files, replay and export (BVH, MP4)."""
