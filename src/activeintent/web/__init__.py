"""The human-in-the-loop web app: a person gives h in the browser (`activeintent serve`)."""
