"""What the project writes: files that appear whole or not at all (`atomic`) and
progress on stderr for long work (`progress`)."""
