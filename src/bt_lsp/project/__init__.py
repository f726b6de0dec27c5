"""The project around the documents: the workspace index of files, file I/O and settings.
The only layer that touches the file system."""
