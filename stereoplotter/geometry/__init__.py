"""Pure, vectorised photogrammetric geometry (chapters 2, 3 and 6 of the book)."""
