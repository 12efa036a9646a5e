"""
The process runtime: the fitting pool, the render pool and what they share
(turns, flights, executors, the fork server, what runs in each worker), and
the HTTP server around the application.
"""
