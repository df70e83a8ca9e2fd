"""servo"""
